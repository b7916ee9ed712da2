//! Per-call cost of the element kernels: ε with D,x, the directional second
//! derivative D,xx[a, b], the mass matrix and the velocity-quadratic force h.

use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_element::*;
use flexmb_rotation::EulerParameters;
use nalgebra::{DMatrix, Vector3};
use std::hint::black_box;

fn config(e: &Element) -> (Vec<f64>, Vec<f64>) {
    // a deformed configuration with velocities (deterministic)
    let mut x = vec![];
    let mut xd = vec![];
    let mut k = 0.0;
    for s in e.slots() {
        match s {
            Slot::Orientation => {
                k += 1.0;
                let l = EulerParameters::from_axis_angle(&Vector3::y_axis(), 0.1 * k);
                x.extend(l.0);
                xd.extend(l.lambda_dot_from_omega(&Vector3::new(0.3, -1.0, 2.0 * k)));
            }
            _ => {
                for i in 0..s.len() {
                    k += 1.0;
                    x.push(0.1 * k + 0.01 * i as f64);
                    xd.push(0.5 - 0.1 * k);
                }
            }
        }
    }
    (x, xd)
}

fn bench_element(c: &mut Criterion, name: &str, e: &Element) {
    let (x, xd) = config(e);
    let (nx, ne) = (e.n_x(), e.n_eps());
    let mut eps = vec![0.0; ne];
    let mut jac = vec![0.0; ne * nx];
    let mut out = vec![0.0; nx * nx];
    let mut g = c.benchmark_group(name);
    if ne > 0 {
        g.bench_function("eps+D,x", |b| {
            b.iter(|| e.deformations_and_jacobian(black_box(&x), None, &mut eps, &mut jac))
        });
        g.bench_function("D,xx[a,b]", |b| {
            b.iter(|| e.deformation_second_derivative(black_box(&x), &xd, &xd, &mut eps))
        });
        let w = vec![1.0; ne];
        g.bench_function("sum w D,xx", |b| {
            b.iter(|| e.deformation_weighted_hessian(black_box(&x), &w, &mut out))
        });
    }
    if e.has_inertia() {
        g.bench_function("mass matrix", |b| {
            b.iter(|| e.mass_matrix(black_box(&x), &mut out))
        });
        let mut h = vec![0.0; nx];
        g.bench_function("h", |b| b.iter(|| e.inertia_h(black_box(&x), &xd, &mut h)));
        let mut d2 = vec![0.0; nx * nx];
        let zero = vec![0.0; nx];
        g.bench_function("dF/dx, dF/dxd", |b| {
            b.iter(|| e.inertia_force_derivatives(black_box(&x), &xd, &zero, &mut out, &mut d2))
        });
    }
    g.finish();
}

fn kernels(c: &mut Criterion) {
    let steel = Material::from_poisson(2.1e11, 0.3, 7600.0);
    let rect = SectionShape::Rectangle {
        by: 0.001,
        bz: 0.03,
    };
    let o = BeamOptions::default();
    let beam = Element::beam(
        [0.0; 3],
        [0.04, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        &steel,
        &rect,
        &o,
    )
    .unwrap();
    bench_element(c, "spatial beam", &beam);
    let sec = rect.properties(0.3).unwrap();
    let mut sbar =
        DMatrix::from_iterator(6, 6, spatial_beam_s_bar(&steel, &sec, 0.04).iter().copied())
            .resize(9, 9, 0.0);
    let mut mbar = DMatrix::from_iterator(
        12,
        12,
        spatial_beam_m_bar(&steel, &sec, 0.04).iter().copied(),
    )
    .resize(15, 15, 0.0);
    for i in 0..3 {
        sbar[(6 + i, 6 + i)] = 1e3;
        mbar[(12 + i, 12 + i)] = 1e-3;
    }
    let r0 = frame_from_axis(&[1.0, 0.0, 0.0], &[0.0, 1.0, 0.0]).unwrap();
    let modes = vec![
        ModeKind::Warping(Side::P),
        ModeKind::Warping(Side::Q),
        ModeKind::Normal { frequency_hz: 1e3 },
    ];
    let se = Element::superelement(
        &LinearSuperelement::from_matrices(0.04, r0, &sbar, &mbar, modes),
        VelocityTransform::B3,
    )
    .unwrap();
    bench_element(c, "superelement k=3", &se);
    bench_element(
        c,
        "spatial hinge",
        &Element::hinge([0.0, 0.0, 1.0], 1.0, 1e3).unwrap(),
    );
    bench_element(
        c,
        "spatial truss",
        &Element::truss([0.0; 3], [1.0, 0.0, 0.0], 1e6, 1.0).unwrap(),
    );
    let body = Element::rigid_body(
        1.0,
        [0.1, 0.0, 0.0],
        [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
        r0,
    )
    .unwrap();
    bench_element(c, "rigid body", &body);
    bench_element(
        c,
        "planar beam",
        &Element::planar_beam([0.0; 2], [0.04, 0.0], &steel, &rect, &o).unwrap(),
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_millis(700)).warm_up_time(std::time::Duration::from_millis(200));
    targets = kernels
}
criterion_main!(benches);
