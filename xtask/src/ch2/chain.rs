//! What the chapter-2 beam scenes share: `n` equal elements in series along
//! x from node N0 at the origin to the tip T, and a run from rest in the
//! reference configuration.

use flexmb_draw::Configuration;
use flexmb_dynamics::{Control, Dynamics, Integrator, SimulationOptions, Trajectory};
use flexmb_model::{Mechanism, Scene};
use std::path::Path;
use std::sync::Arc;

/// One element of a chain: its index k (from 1), its nodes in chain order
/// (N(k−1), then Nk or T for the last) and the scene line of the node it
/// ends at.
pub struct Link {
    /// Element index from 1.
    pub k: usize,
    /// The node it starts at.
    pub from: String,
    /// The node it ends at.
    pub to: String,
}

/// The nodes N1 … N(n−1), T of a chain of `n` elements over length `l`
/// (scene lines, N0 not included) and its links.
pub fn links(n: usize, l: f64) -> (Vec<String>, Vec<Link>) {
    let h = l / n as f64;
    (1..=n)
        .map(|k| {
            let to = if k == n {
                "T".to_string()
            } else {
                format!("N{k}")
            };
            let node = format!(r#"(id: "{to}", at: [{:.15}, 0.0, 0.0])"#, h * k as f64);
            let link = Link {
                k,
                from: format!("N{}", k - 1),
                to,
            };
            (node, link)
        })
        .unzip()
}

/// A built mechanism and its run from rest in the reference configuration.
pub struct Run {
    /// The mechanism.
    pub mech: Arc<Mechanism>,
    /// The trajectory.
    pub trajectory: Trajectory,
}

impl Run {
    /// The configuration at output `k` as the run reached it (its nodal
    /// coordinates x, not solved again from q, which can land on a mirrored
    /// branch of a chain that turned far), to draw.
    pub fn configuration(&self, k: usize) -> Configuration {
        let tr = &self.trajectory;
        Configuration {
            mechanism: self.mech.clone(),
            q: tr.q[k].clone(),
            x: tr.x[k].clone(),
            t: tr.t[k],
            load_scale: 1.0,
        }
    }

    /// The indices of node `id`'s position coordinates.
    pub fn position_of(&self, id: &str) -> Result<Vec<usize>, String> {
        Ok(self
            .mech
            .node(id)
            .ok_or_else(|| format!("{}: no node {id}", self.mech.name))?
            .position
            .clone())
    }
}

/// Builds `scene` (superelement files in `dir`) and integrates it from rest
/// in the reference configuration over 0–`t_end` at `outputs` output times.
pub fn run_from_rest(
    scene: &str,
    dir: &Path,
    integrator: Integrator,
    rtol: f64,
    atol: f64,
    t_end: f64,
    outputs: usize,
) -> Result<Run, String> {
    let scene = Scene::from_ron_str(scene).map_err(|e| e.to_string())?;
    let mech = Arc::new(scene.build(Some(dir)).map_err(|e| e.to_string())?);
    let mut dy = Dynamics::new(mech.clone());
    let q0 = mech.q0();
    let qd0 = vec![0.0; q0.len()];
    let mut opts = SimulationOptions::new(integrator, 0.0, t_end, outputs);
    opts.rtol = rtol;
    opts.atol = atol;
    let trajectory = dy
        .simulate(0.0, &q0, &qd0, &opts, |_, _, _| Control::Continue)
        .map_err(|e| format!("{}: {e}", mech.name))?;
    Ok(Run { mech, trajectory })
}

/// The index of the largest of `values` by `size` (0 for none).
pub fn index_of_largest<T>(values: &[T], size: impl Fn(&T) -> f64) -> usize {
    let mut best = (0, f64::NEG_INFINITY);
    for (k, v) in values.iter().enumerate() {
        let m = size(v);
        if m > best.1 {
            best = (k, m);
        }
    }
    best.0
}
