//! Builds a superelement (constraint modes + 6 normal modes) from a generated
//! solid bar of about 20k DOFs. For the ~100k-DOF figure run
//! `FLEXMB_SE_BENCH_BIG=1 cargo bench -p flexmb-superelement` under
//! `/usr/bin/time -v` (it prints the wall time and VmHWM once).
use criterion::{criterion_group, criterion_main, Criterion};
use flexmb_element::Material;
use flexmb_superelement::{build, parts};
use std::time::Instant;

fn steel() -> Material {
    Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    }
}

fn vm_hwm() -> String {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM"))
                .map(|l| l.to_string())
        })
        .unwrap_or_default()
}

fn bench(c: &mut Criterion) {
    if std::env::var("FLEXMB_SE_BENCH_BIG").is_ok() {
        let part = parts::prismatic_bar(0.4, 0.02, 0.02, [96, 9, 9], steel()).unwrap();
        let t = Instant::now();
        let model = part.mesh.assemble("big bar").unwrap();
        let ta = t.elapsed();
        let mut s = part.settings.clone();
        s.normal_modes = 6;
        let t = Instant::now();
        let se = build(&model, &s).unwrap();
        println!(
            "big: {} DOFs, assembly {:.2?}, build {:.2?}, factor nnz {}, timings {:?}, {}",
            model.n_eq(),
            ta,
            t.elapsed(),
            se.report.factor_nnz,
            se.report.timings,
            vm_hwm()
        );
        return;
    }
    let part = parts::prismatic_bar(0.2, 0.02, 0.02, [40, 5, 5], steel()).unwrap();
    let model = part.mesh.assemble("bar").unwrap();
    let mut s = part.settings.clone();
    s.normal_modes = 6;
    println!("bench model: {} DOFs", model.n_eq());
    let mut g = c.benchmark_group("superelement");
    g.sample_size(10);
    g.bench_function("build_20k_dofs_6_normal_modes", |b| {
        b.iter(|| build(&model, &s).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
