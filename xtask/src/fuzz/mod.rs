//! `cargo xtask fuzz`: mutated scenes through the parser, the validator and
//! one evaluation of the equations of motion, on stable Rust.
//!
//! Each case starts from a scene of `fixtures/scenes/` or `fixtures/fuzz/` and
//! applies one to four mutations, chosen by a seeded generator:
//!
//! * on the RON text ([`text`]): characters and tokens deleted, duplicated,
//!   swapped or inserted; numbers replaced by NaN, ±inf, 0, −1, 1e308, ...;
//!   ids renamed or swapped; entries of a list, map or struct dropped,
//!   duplicated, swapped or taken from another scene; identifiers replaced by
//!   other variant names; the text truncated;
//! * on the parsed [`Scene`](flexmb_model::Scene) ([`structure`]), written back
//!   with `ron`: numbers, element counts `n`, node positions and `position_of`,
//!   element nodes, kinds and options, roles, the choice of DOFs, loads,
//!   controllers, initial velocities, outputs and time functions.
//!
//! The [`harness`] runs each case under `catch_unwind` in a worker thread
//! watched for hangs, and writes an input that panicked or hung to a file
//! with its case seed, from which [`generate`] makes the same text again.

pub mod harness;
pub mod structure;
pub mod text;

use std::path::Path;

/// A small seeded generator (SplitMix64): the same seed gives the same
/// cases on every machine and with every version of the dependencies.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix(self.0)
    }
    /// Uniform in 0..n (0 for n = 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// True with probability p.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    /// One element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
}

fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The seed of case `index` of a run with seed `master`.
pub fn case_seed(master: u64, index: u64) -> u64 {
    mix(master ^ mix(index.wrapping_add(0x5851_f42d_4c95_7f2d)))
}

/// A scene the mutations start from.
#[derive(Clone, Debug)]
pub struct SeedScene {
    /// File name (e.g. `fixtures/scenes/rollup_planar.ron`).
    pub name: String,
    /// Its RON text.
    pub text: String,
    /// How often it is picked relative to the others: a scene with more
    /// than 100 elements (the 720-DOF flexure chain takes 0.4 s to build) an
    /// eighth as often as the small ones.
    pub weight: u32,
}

/// The scenes of `fixtures/scenes/` and `fixtures/fuzz/`, sorted by name so
/// that a seed means the same case in every checkout.
pub fn corpus(root: &Path) -> Result<Vec<SeedScene>, String> {
    let mut out = vec![];
    for dir in ["fixtures/scenes", "fixtures/fuzz"] {
        let d = root.join(dir);
        let rd = std::fs::read_dir(&d).map_err(|e| format!("{}: {e}", d.display()))?;
        // scenes only: not the superelement files (`*.se.ron`) they use
        let mut files: Vec<_> = rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                let n = p.file_name().unwrap_or_default().to_string_lossy();
                n.ends_with(".ron") && !n.ends_with(".se.ron")
            })
            .collect();
        files.sort();
        for p in files {
            let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            let name = format!(
                "{dir}/{}",
                p.file_name().unwrap_or_default().to_string_lossy()
            );
            let parsed = flexmb_model::Scene::from_ron_str(&text);
            // Seeds resolve their superelement files in the fuzz base
            // directory: the chapter-4 scenes keep their ten part files next
            // to them (fixtures/scenes/two_dof_mechanism/) and are far above
            // the fuzz limits (1525 nodal coordinates); they are not seeds.
            let base = harness::base_dir(root);
            if parsed.as_ref().is_ok_and(|s| {
                s.elements.iter().any(|e| match &e.kind {
                    flexmb_model::ElementSpec::Superelement { file, .. } => {
                        !base.join(file).is_file()
                    }
                    _ => false,
                })
            }) {
                continue;
            }
            let big = parsed.is_ok_and(|s| harness::chain_elements(&s) > 100);
            let weight = if big { 1 } else { 8 };
            out.push(SeedScene { name, text, weight });
        }
    }
    if out.is_empty() {
        return Err(format!("no scenes in {}/fixtures", root.display()));
    }
    Ok(out)
}

fn pick_weighted<'a>(corpus: &'a [SeedScene], rng: &mut Rng) -> &'a SeedScene {
    let total: u64 = corpus.iter().map(|s| u64::from(s.weight)).sum();
    let mut r = rng.next_u64() % total.max(1);
    for s in corpus {
        if r < u64::from(s.weight) {
            return s;
        }
        r -= u64::from(s.weight);
    }
    &corpus[corpus.len() - 1]
}

/// One generated input.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Its seed: [`generate`] with this seed gives this case again.
    pub seed: u64,
    /// The scene it started from.
    pub source: String,
    /// The mutations applied, in order.
    pub mutations: Vec<String>,
    /// The mutated RON text.
    pub text: String,
}

/// Makes case `seed` from the corpus: a scene and one to four mutations,
/// each on the parsed scene with probability `structural` (on the text when
/// the text no longer parses), else on the text.
pub fn generate(corpus: &[SeedScene], seed: u64, structural: f64) -> Case {
    let mut rng = Rng::new(seed);
    let src = pick_weighted(corpus, &mut rng);
    let mut text = src.text.clone();
    let mut mutations = vec![];
    // mostly one or two mutations: most cases then still parse
    let k = *rng.pick(&[1, 1, 1, 2, 2, 3, 4]);
    for _ in 0..k {
        let done = rng.chance(structural) && {
            match flexmb_model::Scene::from_ron_str(&text) {
                Ok(mut scene) => {
                    let what = structure::mutate(&mut scene, &mut rng);
                    text = scene.to_ron();
                    mutations.push(format!("scene: {what}"));
                    true
                }
                Err(_) => false,
            }
        };
        if !done {
            let other = &pick_weighted(corpus, &mut rng).text;
            let what = text::mutate(&mut text, other, &mut rng);
            mutations.push(format!("text: {what}"));
        }
    }
    Case {
        seed,
        source: src.name.clone(),
        mutations,
        text,
    }
}
