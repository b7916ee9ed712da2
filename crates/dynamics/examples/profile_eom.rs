use flexmb_model::Scene;
use std::sync::Arc;
use std::time::Instant;
fn main() {
    let mut sc = Scene::load(std::path::Path::new("fixtures/scenes/straight_guidance_spatial.ron")).unwrap();
    if std::env::var("NODAL").is_ok() { sc.dofs = flexmb_model::DofChoice::NodalCoordinates; }
    let m = Arc::new(sc.build(None).unwrap());
    let mut k = flexmb_kinematics::Kinematics::new(m.clone());
    let n = m.n_dof();
    let q: Vec<f64> = m.q0().iter().enumerate().map(|(i, v)| v + 1e-4 * ((i % 7) as f64 - 3.0)).collect();
    let qd: Vec<f64> = (0..n).map(|i| 1e-2 * ((i % 5) as f64 - 2.0)).collect();
    k.solve(&q, 0.0).unwrap(); k.first_order();
    let reps = 2000;
    let mut q2 = q.clone();
    let t0 = Instant::now();
    for r in 0..reps { q2[0] = q[0] + 1e-9 * (r % 3) as f64; k.solve(&q2, 0.0).unwrap(); }
    let a = t0.elapsed().as_secs_f64() / reps as f64;
    println!("solve: {:.1} µs, iterations {}", a * 1e6, k.iterations());
    let t0 = Instant::now();
    for _ in 0..reps { k.first_order(); }
    println!("first_order: {:.1} µs", t0.elapsed().as_secs_f64() / reps as f64 * 1e6);
    let t0 = Instant::now();
    for _ in 0..reps { k.velocities(&qd); }
    println!("velocities: {:.1} µs", t0.elapsed().as_secs_f64() / reps as f64 * 1e6);
    let t0 = Instant::now();
    for _ in 0..reps { k.accelerations(); }
    println!("accelerations: {:.1} µs", t0.elapsed().as_secs_f64() / reps as f64 * 1e6);
    let mut dy = flexmb_dynamics::Dynamics::new(m.clone());
    let mut qdd = vec![0.0; n];
    dy.accelerations(0.0, &q, &qd, &mut qdd).unwrap();
    let t0 = Instant::now();
    for r in 0..reps { q2[0] = q[0] + 1e-9 * (r % 3) as f64; dy.accelerations(0.0, &q2, &qd, &mut qdd).unwrap(); }
    println!("full EOM: {:.1} µs", t0.elapsed().as_secs_f64() / reps as f64 * 1e6);
}
