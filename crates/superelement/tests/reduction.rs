//! Accuracy tests of the builder against independent references: Timoshenko
//! beam theory, the full FE model (sparse shift-invert eigen solves and direct
//! static solves), rigid-body mass properties, and the dense eigensolver.

use flexmb_element::{
    spatial_a_diag, spatial_beam_s_bar, Element, Material, SectionShape, VelocityTransform,
};
use flexmb_superelement::solid::{Block, Mesh};
use flexmb_superelement::{
    build, compatible_interface_pattern, fixed_interface_eigenvalues_dense,
    fixed_interface_eigenvalues_sparse, full_model_clamped_free_frequencies, parts,
    prescribed_rigid_solve, BuildSettings, InterfaceMode, NodeSelection, PointMass,
    RigidBodyProperties, RigidMotion,
};
use nalgebra::{DMatrix, Matrix3, Vector3};

fn steel() -> Material {
    Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    }
}

fn plane_x(x: f64) -> NodeSelection {
    NodeSelection::NearPlane {
        point: [x, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
        tolerance: 1e-9,
    }
}

/// S̄ of a solid bar vs Timoshenko beam theory (EA/l, GJ/l with the series
/// torsion constant of the rectangle, the 4 EI bending entries with Cowper's
/// shear factor), on two meshes. The remaining differences are the FE
/// discretization error plus the end effect of the rigid interfaces (they
/// restrain the Poisson contraction and the torsional warping at the ends), so
/// they shrink with refinement towards a small limit.
#[test]
fn prismatic_bar_matches_timoshenko_and_the_error_shrinks() {
    let (l, b) = (0.2, 0.01);
    let mat = steel();
    let sec = SectionShape::Rectangle { by: b, bz: b }
        .properties(mat.poisson())
        .unwrap();
    let beam = spatial_beam_s_bar(&mat, &sec, l);
    // relative errors of (EA, GJ, EI diagonal, EI coupling)
    let mut errs = Vec::new();
    for n in [[10, 2, 2], [20, 4, 4]] {
        let part = parts::prismatic_bar(l, b, b, n, mat).unwrap();
        let model = part.mesh.assemble("bar").unwrap();
        let se = build(&model, &part.settings).unwrap();
        let s = se.data.s_bar_matrix();
        let rel = |i: usize, j: usize| s[(i, j)] / beam[(i, j)] - 1.0;
        let e = [
            rel(0, 0),
            rel(1, 1),
            rel(2, 2).max(rel(4, 4)),
            rel(2, 3).max(rel(4, 5)),
        ];
        println!(
            "mesh {n:?}: ΔEA {:+.2e} ΔGJ {:+.2e} ΔEI(4) {:+.2e} ΔEI(2) {:+.2e}",
            e[0], e[1], e[2], e[3]
        );
        // no coupling between the six deformations of a doubly symmetric section
        for i in 0..6 {
            for j in 0..6 {
                if beam[(i, j)] == 0.0 {
                    assert!(
                        s[(i, j)].abs() < 1e-6 * s[(i, i)].max(s[(j, j)]),
                        "coupling S̄[{i}][{j}]"
                    );
                }
            }
        }
        // S = AᵀS̄A through the element library
        let el = Element::superelement(&se.data, VelocityTransform::B3).unwrap();
        let a = spatial_a_diag(l);
        for i in 0..6 {
            for j in 0..6 {
                let v = a[i] * s[(i, j)] * a[j];
                assert!((el.stiffness()[(i, j)] - v).abs() <= 1e-12 * v.abs().max(1.0));
            }
        }
        errs.push(e);
    }
    // measured: coarse (+8.5e-3, +2.3e-2, +2.6e-2, +4.2e-2), fine (+5.1e-3, +4.7e-3, +1.25e-2, +2.0e-2)
    for k in 0..4 {
        assert!(
            errs[0][k] > 0.0 && errs[1][k] > 0.0,
            "FE with rigid ends is stiffer than the beam"
        );
        assert!(
            errs[1][k] < errs[0][k],
            "error {k} must shrink with refinement: {errs:?}"
        );
    }
    assert!(
        errs[1][0] < 6e-3 && errs[1][1] < 6e-3,
        "EA, GJ within 0.6 % on the fine mesh"
    );
    assert!(
        errs[1][2] < 1.5e-2 && errs[1][3] < 2.5e-2,
        "EI within 1.5 % / 2.5 %"
    );
}

/// Clamped-free eigenfrequencies of the bar as a superelement (constraint
/// modes + 4 fixed-interface normal modes) vs the full FE model with the same
/// rigid interfaces (sparse shift-invert on the full model).
#[test]
fn bar_superelement_eigenfrequencies_match_the_full_model() {
    let part = parts::prismatic_bar(0.2, 0.01, 0.01, [10, 2, 2], steel()).unwrap();
    let model = part.mesh.assemble("bar").unwrap();
    let mut s = part.settings.clone();
    s.normal_modes = 4;
    let se = build(&model, &s).unwrap();
    let f_se = se.clamped_free_frequencies().unwrap();
    let f_fe = full_model_clamped_free_frequencies(&model, &part.settings, 6).unwrap();
    println!("SE {:?}\nFE {f_fe:?}", &f_se[..6]);
    // measured: 211.240/211.226, 1313.08/1311.53, 3637.04/3623.05 (bending pairs)
    for i in 0..6 {
        let r = f_se[i] / f_fe[i] - 1.0;
        assert!(
            (0.0..1e-2).contains(&(r + 1e-9)),
            "mode {i}: {} vs {}",
            f_se[i],
            f_fe[i]
        );
    }
    assert!(f_se[0] / f_fe[0] - 1.0 < 1e-4);
    // first bending mode vs Euler–Bernoulli: 3.5160/(2π l²) √(EI/ρA) = 211.6 Hz (shear lowers it)
    let eb = 3.516_015 / (2.0 * std::f64::consts::PI * 0.04)
        * (2.1e11f64 * 1e-8 / 12.0 / (7800.0 * 1e-4)).sqrt();
    // measured +0.8 %: the FE bar with rigid ends is slightly stiffer than the beam (see the S̄ test)
    assert!(
        (f_fe[0] / eb - 1.0).abs() < 1.5e-2,
        "{} vs EB {eb}",
        f_fe[0]
    );
}

fn rot_matrix() -> Matrix3<f64> {
    // a generic rotation (axis (1, 2, 3), 0.7 rad)
    nalgebra::Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)),
        0.7,
    )
    .into_inner()
}

/// M̄ reproduces mass, centre of mass and inertia tensor exactly, point masses
/// included: the 6 × 6 rigid-body mass from M̄ (rigid v̄) equals the FE mass
/// matrix applied to the rigid displacement fields plus the point masses'
/// analytic contributions. The part is rotated so that R0 ≠ I.
#[test]
fn m_bar_reproduces_rigid_body_properties_with_point_masses() {
    let q = rot_matrix();
    let part = parts::box_arm(0.1, 0.03, 0.02, 0.002, 6, 4, steel()).unwrap();
    let mut mesh = part.mesh.clone();
    let rotate = |p: [f64; 3]| -> [f64; 3] {
        let v = q * Vector3::from(p);
        [v[0], v[1], v[2]]
    };
    for c in mesh.coords.iter_mut() {
        *c = rotate(*c);
    }
    let model = mesh.assemble("arm").unwrap();
    let ex = rotate([1.0, 0.0, 0.0]);
    let plane = |x: f64| NodeSelection::NearPlane {
        point: rotate([x, 0.0, 0.0]),
        normal: ex,
        tolerance: 1e-9,
    };
    let mut s = BuildSettings::new(
        rotate([0.0; 3]),
        rotate([0.1, 0.0, 0.0]),
        plane(0.0),
        plane(0.1),
    );
    s.y_axis = Some(rotate([0.3, 1.0, 0.2]));
    // a one-node mass, a coil on a rigid link with rotary inertia, a mass on interface q
    let node = model.coords().iter().position(|c| {
        let l = q.transpose() * Vector3::from(*c);
        (l[0] - 0.05).abs() < 1e-12 && (l[1] - 0.015).abs() < 1e-12 && (l[2] - 0.01).abs() < 1e-12
    });
    let node = node.expect("a corner node at x = 0.05");
    let jc = [[2e-6, 1e-7, 0.0], [1e-7, 3e-6, -2e-7], [0.0, -2e-7, 1.5e-6]];
    let coil_pos = rotate([0.03, 0.0, 0.02]);
    s.point_masses = vec![
        PointMass {
            name: "sensor".into(),
            mass: 0.005,
            position: model.coords()[node],
            inertia: None,
            nodes: NodeSelection::Ids(vec![model.node_ids()[node]]),
        },
        PointMass {
            name: "coil".into(),
            mass: 0.02,
            position: coil_pos,
            inertia: Some(jc),
            nodes: NodeSelection::NearSegment {
                a: rotate([0.02, 0.0, 0.01]),
                b: rotate([0.04, 0.0, 0.01]),
                radius: 0.004,
            },
        },
        PointMass {
            name: "clamp".into(),
            mass: 0.01,
            position: rotate([0.105, 0.0, 0.0]),
            inertia: None,
            nodes: plane(0.1),
        },
    ];
    let se = build(&model, &s).unwrap();
    let r0 = Matrix3::from_fn(|i, j| se.data.r0[i][j]);
    assert!((r0.column(0) - Vector3::from(ex)).norm() < 1e-14);
    let p = Vector3::from(s.p);
    // reference: FE rigid fields (about p, element-frame components) + point masses
    let mut m6 = DMatrix::<f64>::zeros(6, 6);
    let fields: Vec<Vec<f64>> = (0..6)
        .map(|k| {
            let mut tb = Vector3::zeros();
            let mut wb = Vector3::zeros();
            if k < 3 {
                tb[k] = 1.0
            } else {
                wb[k - 3] = 1.0
            }
            let (t, w) = (r0 * tb, r0 * wb);
            model.rigid_field([t[0], t[1], t[2]], [w[0], w[1], w[2]], s.p)
        })
        .collect();
    let mk = model.m().to_dense();
    let md = DMatrix::from_fn(model.n_eq(), model.n_eq(), |i, j| {
        if i <= j {
            mk[(i, j)]
        } else {
            mk[(j, i)]
        }
    });
    for a in 0..6 {
        for b in 0..6 {
            let ua = nalgebra::DVector::from_vec(fields[a].clone());
            let ub = nalgebra::DVector::from_vec(fields[b].clone());
            m6[(a, b)] = ua.dot(&(&md * ub));
        }
    }
    let add_point = |m6: &mut DMatrix<f64>, m: f64, c: Vector3<f64>, j: Matrix3<f64>| {
        let cb = r0.transpose() * (c - p);
        let mut g = nalgebra::SMatrix::<f64, 3, 6>::zeros();
        g.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&Matrix3::identity());
        g.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-cb.cross_matrix()));
        let mut h = nalgebra::SMatrix::<f64, 3, 6>::zeros();
        h.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&Matrix3::identity());
        let jb = r0.transpose() * j * r0;
        let add = g.transpose() * g * m + h.transpose() * jb * h;
        for a in 0..6 {
            for b in 0..6 {
                m6[(a, b)] += add[(a, b)];
            }
        }
    };
    add_point(
        &mut m6,
        0.005,
        Vector3::from(model.coords()[node]),
        Matrix3::zeros(),
    );
    add_point(
        &mut m6,
        0.02,
        Vector3::from(coil_pos),
        Matrix3::from_fn(|i, j| jc[i][j]),
    );
    add_point(
        &mut m6,
        0.01,
        Vector3::from(rotate([0.105, 0.0, 0.0])),
        Matrix3::zeros(),
    );
    // from M̄
    let rb = RigidBodyProperties::from_m_bar(&se.data.m_bar_matrix(), se.data.l0);
    let rf = RigidBodyProperties::from_rigid_mass(&m6);
    let scale_m = rf.mass;
    println!(
        "mass {} vs {}, com {:?} vs {:?}",
        rb.mass, rf.mass, rb.com, rf.com
    );
    assert!((rb.mass - rf.mass).abs() < 1e-10 * scale_m);
    let mass_fe = 7800.0 * (0.1 * (0.03 * 0.02 - 0.026 * 0.016));
    assert!(
        (rf.mass - (mass_fe + 0.035)).abs() < 1e-12 * rf.mass,
        "analytic mass of the tube + masses"
    );
    for d in 0..3 {
        assert!((rb.com[d] - rf.com[d]).abs() < 1e-10 * 0.1, "com {d}");
    }
    let jscale = rf.inertia[0][0]
        .abs()
        .max(rf.inertia[1][1])
        .max(rf.inertia[2][2]);
    for i in 0..3 {
        for j in 0..3 {
            assert!(
                (rb.inertia[i][j] - rf.inertia[i][j]).abs() < 1e-10 * jscale,
                "inertia {i}{j}: {} vs {}",
                rb.inertia[i][j],
                rf.inertia[i][j]
            );
        }
    }
}

/// Table 3.1 analogue: the thin-walled box arm clamped at p with a tip mass
/// rigidly attached at q; superelements with 0, 1, 2, 4, 6 fixed-interface
/// normal modes vs the full FE model. Nested Ritz subspaces: every frequency
/// error decreases monotonically with k.
#[test]
fn normal_modes_converge_monotonically_to_the_full_model() {
    let part = parts::box_arm(0.12, 0.03, 0.02, 0.0015, 8, 4, steel()).unwrap();
    let model = part.mesh.assemble("arm").unwrap();
    let mut s = part.settings.clone();
    s.point_masses.push(PointMass {
        name: "tip".into(),
        mass: 0.01,
        position: [0.13, 0.0, 0.0],
        inertia: None,
        nodes: plane_x(0.12),
    });
    let f_fe = full_model_clamped_free_frequencies(&model, &s, 6).unwrap();
    println!("FE     {:?}", f_fe);
    let mut prev: Option<Vec<f64>> = None;
    let mut errs_last = Vec::new();
    for k in [0usize, 1, 2, 4, 6] {
        s.normal_modes = k;
        let se = build(&model, &s).unwrap();
        let f = se.clamped_free_frequencies().unwrap();
        let err: Vec<f64> = (0..6).map(|i| f[i] / f_fe[i] - 1.0).collect();
        println!(
            "SE-CF{k} {:?}\n   err {:?}",
            &f[..6],
            err.iter().map(|e| format!("{e:.2e}")).collect::<Vec<_>>()
        );
        for i in 0..6 {
            assert!(err[i] > -1e-9, "Ritz values bound from above");
            if let Some(pe) = &prev {
                assert!(
                    err[i] <= pe[i] + 1e-9,
                    "mode {i} must not get worse at k = {k}"
                );
            }
        }
        prev = Some(err.clone());
        errs_last = err;
    }
    // measured relative errors at k = 0: (8.9e-3, 8.3e-3, 0.14, 0.69, 0.66, 0.62);
    // at k = 6: (6.2e-4, 1.4e-3, 2.4e-2, 2.0e-2, 8e-7, 6e-8)
    assert!(errs_last.iter().all(|e| *e < 3e-2), "{errs_last:?}");
    assert!(
        errs_last[0] < 1e-3 && errs_last[1] < 2e-3 && errs_last[4] < 1e-5 && errs_last[5] < 1e-5
    );
}

/// Dense vs sparse generalized eigensolvers on the fixed-interface problem of
/// a small model.
#[test]
fn dense_and_sparse_eigensolvers_agree() {
    let part = parts::prismatic_bar(0.05, 0.01, 0.006, [4, 2, 1], steel()).unwrap();
    let model = part.mesh.assemble("small").unwrap();
    let dense = fixed_interface_eigenvalues_dense(&model, &part.settings).unwrap();
    let sparse = fixed_interface_eigenvalues_sparse(&model, &part.settings, 8).unwrap();
    println!("dense {:?}\nsparse {:?}", &dense[..8], sparse);
    for i in 0..8 {
        assert!(
            (dense[i] / sparse[i] - 1.0).abs() < 1e-9,
            "eigenvalue {i}: {} vs {}",
            dense[i],
            sparse[i]
        );
    }
}

/// Chain assembly of superelements' linear stiffness over (µ̄p, µ̄q, η_p, η_q)
/// with shared boundary nodes and shared warping coordinates; returns the
/// torsional stiffness with node 0 clamped, node n twisted by 1 rad (other
/// DOFs fixed) and warping suppressed (η = 0) at both ends.
fn chain_torsion(ks: &[DMatrix<f64>], warping: bool) -> f64 {
    let n = ks.len();
    let nw = if warping { n + 1 } else { 0 };
    let ndof = 6 * (n + 1) + nw;
    let mut k = DMatrix::<f64>::zeros(ndof, ndof);
    for (e, ke) in ks.iter().enumerate() {
        let mut map: Vec<usize> = (0..12).map(|i| 6 * e + i).collect();
        if warping {
            map.push(6 * (n + 1) + e);
            map.push(6 * (n + 1) + e + 1);
        }
        assert_eq!(map.len(), ke.nrows());
        for (a, &ga) in map.iter().enumerate() {
            for (b, &gb) in map.iter().enumerate() {
                k[(ga, gb)] += ke[(a, b)];
            }
        }
    }
    let mut fixed: Vec<usize> = (0..6).chain(6 * n..6 * n + 6).collect();
    if warping {
        fixed.push(6 * (n + 1));
        fixed.push(6 * (n + 1) + n);
    }
    let free: Vec<usize> = (0..ndof).filter(|i| !fixed.contains(i)).collect();
    let mut g = nalgebra::DVector::<f64>::zeros(ndof);
    g[6 * n + 3] = 1.0;
    let kff = DMatrix::from_fn(free.len(), free.len(), |i, j| k[(free[i], free[j])]);
    let rhs = nalgebra::DVector::from_fn(free.len(), |i, _| -(k.row(free[i]) * &g)[0]);
    let x = kff.cholesky().unwrap().solve(&rhs);
    let mut u = g.clone();
    for (i, &f) in free.iter().enumerate() {
        u[f] = x[i];
    }
    (u.transpose() * &k * &u)[0]
}

/// The short wide sheet flexure of thesis Fig. 3.9 (l = h = 40 mm,
/// t = 0.3 mm, steel), clamped at both ends (warping suppressed there). Four
/// superelements in series with constraint modes only (SE-C) suppress the
/// warping at the three inner interfaces too and are far too stiff in torsion;
/// with warping modes shared between neighbours and suppressed at the ends
/// (SE-CW) they match the full FE model.
#[test]
fn warping_modes_give_the_torsional_stiffness_of_the_clamped_sheet() {
    let (l, h, t) = (0.04, 0.04, 3e-4);
    let mat = steel();
    let nseg = 4;
    // full model: one mesh over the whole sheet, both ends rigid (clamped / twisted)
    let full = parts::sheet_segment(0.0, l, h, t, [16, 10, 1], mat).unwrap();
    let model = full.mesh.assemble("sheet").unwrap();
    let theta = 1e-3;
    let (_, energy) = prescribed_rigid_solve(
        &model,
        &plane_x(0.0),
        &plane_x(l),
        &RigidMotion {
            translation: [0.0; 3],
            rotation: [theta, 0.0, 0.0],
            about: [l, 0.0, 0.0],
        },
    )
    .unwrap();
    let k_fe = 2.0 * energy / (theta * theta);
    // a single superelement over the whole sheet reproduces it exactly (constraint mode V10)
    let se_full = build(&model, &full.settings).unwrap();
    println!(
        "single SE {} vs prescribed solve {k_fe}",
        se_full.data.s_bar[1][1]
    );
    // (the quadratic forms of the thin sheet lose ~6 digits to cancellation of the
    // stiff in-plane terms, so the two computations agree to ~1e-6)
    assert!((se_full.data.s_bar[1][1] / k_fe - 1.0).abs() < 1e-5);
    // Saint-Venant (free warping): GJ/l
    let j = flexmb_element::rectangle_torsion_constant(h, t);
    let k_sv = mat.g * j / l;
    // the chain
    let mut kc = Vec::new();
    let mut kw = Vec::new();
    let mut segs = Vec::new();
    for e in 0..nseg {
        let len = l / nseg as f64;
        let part = parts::sheet_segment(e as f64 * len, len, h, t, [4, 10, 1], mat).unwrap();
        let m = part.mesh.assemble(&format!("segment {e}")).unwrap();
        let c = build(&m, &part.settings).unwrap();
        kc.push(c.k_full.clone());
        let mut s = part.settings.clone();
        s.warping_p = true;
        s.warping_q = true;
        let w = build(&m, &s).unwrap();
        kw.push(w.k_full.clone());
        segs.push((m, w));
    }
    // neighbours' warping modes are compatible (mirror-symmetric identical segments)
    let (ma, wa) = &segs[0];
    let (mb, wb) = &segs[1];
    let mut diff: f64 = 0.0;
    let mut mag: f64 = 0.0;
    for (ia, ca) in ma.coords().iter().enumerate() {
        if (ca[0] - l / 4.0).abs() > 1e-12 {
            continue;
        }
        let ib = mb
            .coords()
            .iter()
            .position(|cb| (0..3).all(|d| (cb[d] - ca[d]).abs() < 1e-12))
            .unwrap();
        let ua = wa.node_displacement(13, ia);
        let ub = wb.node_displacement(12, ib);
        for d in 0..3 {
            diff = diff.max((ua[d] - ub[d]).abs());
            mag = mag.max(ua[d].abs());
        }
    }
    println!(
        "warping mode mismatch at the shared interface {:.2e} (max {mag:.2e})",
        diff
    );
    assert!(diff < 1e-8 * mag);
    let k_c = chain_torsion(&kc, false);
    let k_w = chain_torsion(&kw, true);
    println!(
        "torsional stiffness [N m/rad]: full FE {k_fe:.5}, SE-C x4 {k_c:.5} ({:+.1} %), SE-CW x4 {k_w:.5} ({:+.2} %), \
         Saint-Venant GJ/l {k_sv:.5}",
        100.0 * (k_c / k_fe - 1.0),
        100.0 * (k_w / k_fe - 1.0)
    );
    assert!(
        k_fe > 1.3 * k_sv,
        "clamping the warping stiffens the short sheet"
    );
    assert!(
        k_c > 2.0 * k_fe,
        "SE-C suppresses warping at every interface"
    );
    assert!(
        (k_w / k_fe - 1.0).abs() < 0.05,
        "SE-CW within 5 % of the full model"
    );
    assert!((k_w / k_fe - 1.0).abs() < 0.1 * (k_c / k_fe - 1.0));
}

/// Compatible warping modes (§3.4.2) of two adjoining parts with different
/// shear moduli coincide on the shared interface, while the parts' own (3.4)
/// warping modes do not.
#[test]
fn compatible_modes_of_different_parts_coincide_on_the_interface() {
    let a = steel();
    let b = Material {
        e: 2.1e11,
        g: 1.0e11,
        rho: 7800.0,
    };
    let (la, by, bz) = (0.02, 0.012, 0.003);
    let h = [la / 4.0, by / 6.0, bz / 2.0];
    let block = |x0: f64, m: usize| Block {
        min: [x0, -0.5 * by, -0.5 * bz],
        max: [x0 + la, 0.5 * by, 0.5 * bz],
        material: m,
    };
    let ab = Mesh::boxes(&[block(0.0, 0), block(la, 1)], &[a, b], h)
        .unwrap()
        .assemble("A+B")
        .unwrap();
    let pattern = compatible_interface_pattern(
        &ab,
        &plane_x(0.0),
        &plane_x(2.0 * la),
        &RigidMotion {
            translation: [0.0; 3],
            rotation: [1.0, 0.0, 0.0],
            about: [2.0 * la, 0.0, 0.0],
        },
        &plane_x(la),
    )
    .unwrap();
    let ma = Mesh::boxes(&[block(0.0, 0)], &[a, b], h)
        .unwrap()
        .assemble("A")
        .unwrap();
    let mb = Mesh::boxes(&[block(la, 1)], &[a, b], h)
        .unwrap()
        .assemble("B")
        .unwrap();
    let mut sa = BuildSettings::new([0.0; 3], [la, 0.0, 0.0], plane_x(0.0), plane_x(la));
    let mut sb = BuildSettings::new(
        [la, 0.0, 0.0],
        [2.0 * la, 0.0, 0.0],
        plane_x(la),
        plane_x(2.0 * la),
    );
    sa.warping_q = true;
    sb.warping_p = true;
    sa.interface_modes.push(InterfaceMode {
        side: flexmb_element::Side::Q,
        name: "compatible warping".into(),
        pattern: pattern.clone(),
    });
    sb.interface_modes.push(InterfaceMode {
        side: flexmb_element::Side::P,
        name: "compatible warping".into(),
        pattern,
    });
    let sea = build(&ma, &sa).unwrap();
    let seb = build(&mb, &sb).unwrap();
    // columns: 12 = own warping mode, 13 = compatible mode
    let (mut d_comp, mut d_own, mut mag_c, mut mag_o) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut count = 0;
    for (ia, ca) in ma.coords().iter().enumerate() {
        if (ca[0] - la).abs() > 1e-12 {
            continue;
        }
        count += 1;
        let ib = mb
            .coords()
            .iter()
            .position(|cb| (0..3).all(|d| (cb[d] - ca[d]).abs() < 1e-12))
            .unwrap();
        let (ca13, cb13) = (sea.node_displacement(13, ia), seb.node_displacement(13, ib));
        let (ca12, cb12) = (sea.node_displacement(12, ia), seb.node_displacement(12, ib));
        for d in 0..3 {
            d_comp = d_comp.max((ca13[d] - cb13[d]).abs());
            d_own = d_own.max((ca12[d] - cb12[d]).abs());
            mag_c = mag_c.max(ca13[d].abs());
            mag_o = mag_o.max(ca12[d].abs());
        }
    }
    println!(
        "{count} interface nodes: compatible modes differ by {d_comp:.2e} (max {mag_c:.2e}), own (3.4) modes by \
         {d_own:.2e} (max {mag_o:.2e})"
    );
    assert!(count > 10);
    assert!(d_comp <= 1e-12 * mag_c.max(1e-300) || d_comp < 1e-12);
    assert!(
        d_own > 1e-3 * mag_o,
        "the parts' own warping modes are not compatible"
    );
}
