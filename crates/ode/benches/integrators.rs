//! Per-step overhead of the integrators on a 44-dimensional linear system:
//! a chain of 22 unit masses joined by unit springs (first mass tied to the
//! ground), light damping, integrated over [0, 20] from a displaced state.
//! The right-hand side costs O(n), so the timings are dominated by the
//! integrators' own work. Each benchmark prints its statistics once, so the
//! time per step can be read off.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use faer::Mat;
use flexmb_ode::{
    Adams, AdamsOptions, Dopri5, Dopri5Options, GeneralizedAlpha, GeneralizedAlphaOptions,
    OdeSystem, Output, RhsError, SecondOrderSystem,
};

const MASSES: usize = 22;
const K: f64 = 1.0;
const C: f64 = 0.01;
const T_END: f64 = 20.0;

/// Spring forces of the chain: f_i = −Σ k (q_i − q_j) − c q̇_i.
fn forces(q: &[f64], qd: &[f64], f: &mut [f64]) {
    let n = q.len();
    for i in 0..n {
        let left = if i == 0 { 0.0 } else { q[i - 1] };
        let mut fi = -K * (q[i] - left) - C * qd[i];
        if i + 1 < n {
            fi -= K * (q[i] - q[i + 1]);
        }
        f[i] = fi;
    }
}

struct ChainFirstOrder;

impl OdeSystem for ChainFirstOrder {
    fn dim(&self) -> usize {
        2 * MASSES
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let (q, qd) = y.split_at(MASSES);
        let (dq, dqd) = dy.split_at_mut(MASSES);
        dq.copy_from_slice(qd);
        forces(q, qd, dqd);
        Ok(())
    }
}

struct ChainSecondOrder {
    f: Vec<f64>,
}

impl SecondOrderSystem for ChainSecondOrder {
    fn dim(&self) -> usize {
        MASSES
    }
    fn residual(
        &mut self,
        _t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), RhsError> {
        forces(q, qd, &mut self.f);
        for i in 0..MASSES {
            r[i] = qdd[i] - self.f[i];
        }
        Ok(())
    }
    fn tangent(
        &mut self,
        _t: f64,
        _q: &[f64],
        _qd: &[f64],
        _qdd: &[f64],
        m: &mut Mat<f64>,
        c: &mut Mat<f64>,
        k: &mut Mat<f64>,
    ) -> Result<(), RhsError> {
        m.fill(0.0);
        c.fill(0.0);
        k.fill(0.0);
        for i in 0..MASSES {
            m[(i, i)] = 1.0;
            c[(i, i)] = C;
            k[(i, i)] = if i + 1 < MASSES { 2.0 * K } else { K };
            if i + 1 < MASSES {
                k[(i, i + 1)] = -K;
                k[(i + 1, i)] = -K;
            }
        }
        Ok(())
    }
}

fn initial() -> (Vec<f64>, Vec<f64>) {
    let q0: Vec<f64> = (0..MASSES)
        .map(|i| 0.1 * (i as f64 + 1.0) / MASSES as f64)
        .collect();
    (q0, vec![0.0; MASSES])
}

fn bench(c: &mut Criterion) {
    let (q0, qd0) = initial();
    let y0: Vec<f64> = q0.iter().chain(&qd0).copied().collect();
    let mut group = c.benchmark_group("chain44");
    group.sample_size(20);

    let dopri = Dopri5::new(Dopri5Options::default().rtol(1e-6).atol(1e-8));
    let adams = Adams::new(AdamsOptions::default().rtol(1e-6).atol(1e-8));
    let ga = GeneralizedAlpha::new(GeneralizedAlphaOptions::default().rtol(1e-4).atol(1e-6));

    let s = dopri
        .solve(&mut ChainFirstOrder, 0.0, &y0, T_END, &Output::Final)
        .unwrap();
    println!("dopri5: {}", s.stats);
    let s = adams
        .solve(&mut ChainFirstOrder, 0.0, &y0, T_END, &Output::Final)
        .unwrap();
    println!("adams: {}", s.stats);
    let mut so = ChainSecondOrder {
        f: vec![0.0; MASSES],
    };
    let s = ga
        .solve(&mut so, 0.0, &q0, &qd0, T_END, &Output::Final)
        .unwrap();
    println!("generalized-alpha: {}", s.stats);

    group.bench_function("dopri5_rtol1e-6", |b| {
        b.iter(|| {
            dopri
                .solve(
                    &mut ChainFirstOrder,
                    0.0,
                    black_box(&y0),
                    T_END,
                    &Output::Final,
                )
                .unwrap()
        })
    });
    group.bench_function("adams_rtol1e-6", |b| {
        b.iter(|| {
            adams
                .solve(
                    &mut ChainFirstOrder,
                    0.0,
                    black_box(&y0),
                    T_END,
                    &Output::Final,
                )
                .unwrap()
        })
    });
    group.bench_function("generalized_alpha_rtol1e-4", |b| {
        b.iter(|| {
            ga.solve(&mut so, 0.0, black_box(&q0), &qd0, T_END, &Output::Final)
                .unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
