//! Chapter 3 §3.5.2's claims on the complex-shaped component (Table 3.1),
//! on our designed part (xtask/src/ch3/component.rs) and its stored
//! CalculiX solid of the same mesh:
//! - flexmb's full FE model and CalculiX agree (the same model in two codes);
//! - the constraint modes alone (SE-C) give the first three modes;
//! - each added normal mode brings in one more frequency (SE-CF1 mode 4,
//!   SE-CF2 mode 5), and SE-C lacks both;
//! - six normal modes bring little on the modes SE-CF2 has already;
//! - the scene (superelement, rigid link, point mass) has the frequencies
//!   of the superelement built with the mass on its interface.

use xtask::ch3::component::{self as comp, Geometry, N_FREQ};
use xtask::progress::Progress;

#[test]
fn the_component_shows_the_pattern_of_table_3_1() {
    let root = xtask::workspace_root();
    let solid = comp::read_solid(&root).unwrap();
    let dir = std::env::temp_dir().join(format!("flexmb-ch3-component-{}", std::process::id()));
    let c = comp::compute(&dir, &Geometry::default(), &Progress::hidden());
    let _ = std::fs::remove_dir_all(&dir);
    let c = c.unwrap();
    // the same model in two codes: the C3D20 mesh of research/ch3/boxmesh.py
    // is flexmb's, so the frequencies agree to the solvers' precision (3.5e-7
    // measured; CalculiX prints seven digits)
    for k in 0..N_FREQ {
        assert!(
            (c.full[k] / solid[k] - 1.0).abs() < 2e-6,
            "mode {}: flexmb {} Hz, CalculiX {} Hz",
            k + 1,
            c.full[k],
            solid[k]
        );
    }
    let dofs: Vec<usize> = c.models.iter().map(|m| m.dof).collect();
    assert_eq!(dofs, [6, 7, 8, 12]);
    let a: Vec<Vec<Option<f64>>> = c
        .models
        .iter()
        .map(|m| comp::assign(&solid[..N_FREQ], &m.freqs))
        .collect();
    for (m, r) in c.models.iter().zip(&a) {
        eprintln!("{}: {:?} (all {:?})", m.name, r, m.freqs);
    }
    let has = |m: usize| -> Vec<usize> {
        (0..N_FREQ)
            .filter(|&k| a[m][k].is_some())
            .map(|k| k + 1)
            .collect()
    };
    // the thesis's pattern: SE-C 1, 2, 3, 6; SE-CF1 adds 4; SE-CF2 adds 5
    assert_eq!(has(0), [1, 2, 3, 6]);
    assert_eq!(has(1), [1, 2, 3, 4, 6]);
    assert_eq!(has(2), [1, 2, 3, 4, 5, 6]);
    assert_eq!(has(3), [1, 2, 3, 4, 5, 6]);
    let err = |m: usize, k: usize| a[m][k].map(|f| f / solid[k] - 1.0).unwrap();
    // SE-C's first three within 2 % (ours 1.83 % on mode 2; the thesis's
    // SE-C is within 1.6 % on its modes 1-3)
    for k in 0..3 {
        assert!(err(0, k).abs() < 0.02, "SE-C mode {}: {}", k + 1, err(0, k));
    }
    // the modes a normal mode brings in are accurate at once (0.41 % and
    // 0.30 % measured; the thesis's 0.0 % and 0.09 %)
    assert!(err(1, 3).abs() < 0.01 && err(2, 4).abs() < 0.01);
    // and SE-C has no frequency within 10 % of either
    for f in &c.models[0].freqs {
        for k in [3, 4] {
            assert!(
                (f / solid[k] - 1.0).abs() > comp::MATCH,
                "SE-C {f} Hz near mode {}",
                k + 1
            );
        }
    }
    // six normal modes: on modes 1-5 no worse than two and at most a quarter
    // of a per cent better (the thesis: at most 1.5 points, on mode 3)
    for k in 0..5 {
        let (e2, e6) = (err(2, k).abs(), err(3, k).abs());
        assert!(
            e6 <= e2 + 1e-12 && e2 - e6 < 0.0025,
            "mode {}: SE-CF2 {e2}, SE-CF6 {e6}",
            k + 1
        );
    }
}

/// The scene's frequencies (superelement + rigid beam + point mass, the
/// equations of motion linearized at rest (E.6)) against the builder's own
/// clamped-free frequencies of the superelement with the mass attached to
/// its interface q (M̄ with the point mass, K̄): two paths through the code
/// to the same linear problem, which agree to 1.1e-7 relative (measured on
/// this coarse mesh; the builder's boundary block carries the rounding of
/// the FE stiffness's rigid-body null space, the scene's deformations do not).
#[test]
fn the_components_scene_has_the_superelements_frequencies() {
    use flexmb_superelement::build;
    let g = Geometry {
        h: [0.0125, 0.0075],
        ..Geometry::default()
    };
    let (mesh, settings) = comp::part(&g).unwrap();
    let model = mesh.assemble("component").unwrap();
    let dir =
        std::env::temp_dir().join(format!("flexmb-ch3-component-scene-{}", std::process::id()));
    for k in [0, 2] {
        let mut s = settings.clone();
        s.normal_modes = k;
        let r = build(&model, &s).unwrap();
        let file = comp::file_of(k);
        std::fs::create_dir_all(&dir).unwrap();
        flexmb_superelement::spec::write_ron(&dir.join(&file), &r.data).unwrap();
        let (dof, scene) = comp::scene_frequencies(&dir, &file).unwrap();
        s.point_masses.push(comp::tip_mass());
        let with_mass = build(&model, &s)
            .unwrap()
            .clamped_free_frequencies()
            .unwrap();
        assert_eq!(dof, 6 + k);
        for (a, b) in scene.iter().zip(&with_mass) {
            assert!(
                (a / b - 1.0).abs() < 1e-6,
                "{k} normal modes: scene {scene:?}, builder {with_mass:?}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
