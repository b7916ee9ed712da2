//! The chain helpers of the elements stage ([`BuildStage::Elements`]): how
//! many elements a chain makes, its memory estimate and its intermediate
//! nodes.

use super::*;

/// The most elements one chain helper may make.
pub(crate) const MAX_CHAIN_N: usize = 1_000_000;

/// Memory per element of an assembled mechanism, measured on a spatial beam
/// chain (element data, names, sparse Jacobian rows, role bookkeeping), with a margin.
pub(super) const BYTES_PER_ELEMENT: f64 = 20e3;

pub(super) fn chain_n(k: &ElementSpec) -> usize {
    match k {
        ElementSpec::Beam(b) => b.n,
        ElementSpec::Truss { n, .. } => *n,
        _ => 1,
    }
}

pub(super) fn default_up(axis: &[f64; 3]) -> [f64; 3] {
    let a = Vector3::from(*axis).normalize();
    if a.z.abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// The node pairs of a chain of `n` elements from p to q, creating the
/// intermediate nodes `ID.n1` … `ID.n(n−1)`.
pub(super) fn chain_nodes(
    id: &str,
    ends: &(String, String),
    p: &[f64],
    q: &[f64],
    n: usize,
    node_at: &mut BTreeMap<String, Vec<f64>>,
    order: &mut Vec<String>,
) -> Result<Vec<(String, String)>, ModelError> {
    let mut names = vec![ends.0.clone()];
    for k in 1..n {
        let name = format!("{id}.n{k}");
        let t = k as f64 / n as f64;
        let at: Vec<f64> = p.iter().zip(q).map(|(a, b)| a + t * (b - a)).collect();
        if node_at.insert(name.clone(), at).is_some() {
            return Err(ModelError::DuplicateId {
                kind: "node (made by the chain helper)",
                id: name,
            });
        }
        order.push(name.clone());
        names.push(name);
    }
    names.push(ends.1.clone());
    Ok(names
        .windows(2)
        .map(|w| (w[0].clone(), w[1].clone()))
        .collect())
}
