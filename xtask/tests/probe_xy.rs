#[test]
#[ignore]
fn probe_directions() {
    let root = xtask::workspace_root();
    let (mech, dofs) = xtask::ch7::mechanism(&root, false, None).unwrap();
    for p in [[0.0, -0.05], [-0.0167, -0.0167], [-0.05, -0.05]] {
        let r = xtask::ch7xy::held_equilibria(&mech, dofs, &[p], 1, &|_, _| {});
        println!(
            "{p:?}: {}",
            match r {
                Ok(v) => format!("ok {:?}", v[0].frequencies_hz),
                Err(e) => e,
            }
        );
    }
}
