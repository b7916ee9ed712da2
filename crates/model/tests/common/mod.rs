//! Helpers shared by the scene tests.

use flexmb_model::{Mechanism, Scene};

/// Parses and builds a scene from RON text; the error as text.
pub fn build(text: &str) -> Result<Mechanism, String> {
    Scene::from_ron_str(text)
        .and_then(|s| s.build(None))
        .map_err(|e| e.to_string())
}
