//! `flexmb draw`: the guidance at its static equilibrium is drawn where
//! `flexmb static` puts it, and the command writes the figure it is asked
//! for (SVG or PNG, any configuration).

mod common;
use common::{fixture, flexmb, temp_dir};

use flexmb_draw::{geometry, Configuration, View};
use flexmb_model::Scene;
use std::sync::Arc;

/// The position of node `id` in `flexmb static`'s node_positions.csv.
fn static_position(scene: &str, id: &str, dir: &std::path::Path) -> Vec<f64> {
    let out = dir.join("static");
    let o = flexmb()
        .args(["static", &fixture(scene).display().to_string(), "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(out.join("node_positions.csv")).unwrap();
    let names: Vec<&str> = text
        .lines()
        .find_map(|l| l.strip_prefix("# rows: nodes "))
        .unwrap()
        .split(' ')
        .collect();
    let k = names.iter().position(|n| *n == id).unwrap();
    let (_, rows) = flexmb_plot::read_csv(&out.join("node_positions.csv")).unwrap();
    rows[k].clone()
}

#[test]
fn the_body_is_drawn_where_flexmb_static_puts_it() {
    let dir = temp_dir("draw", "static");
    for (scene, view) in [
        ("straight_guidance_spatial.ron", View::Iso),
        ("straight_guidance_planar.ron", View::Xy),
    ] {
        let s = static_position(scene, "S", &dir);
        let path = fixture(scene);
        let mech = Arc::new(Scene::load(&path).unwrap().build(path.parent()).unwrap());
        let at = Configuration::static_equilibrium(&mech).unwrap();
        let g = geometry(&at.mechanism, &at.x, view);
        // S is the second node of the beam body1 (B, S)
        let body1 = g.items.iter().find(|i| i.id == "body1").unwrap();
        let p = body1.model[1];
        // the loads act at t > 0 only: the equilibrium is gravity's (spatial)
        // or the reference (planar); S moved in the spatial case
        for (c, v) in s.iter().enumerate() {
            assert!((p[c] - v).abs() < 1e-11, "{scene}: S[{c}] {} vs {v}", p[c]);
        }
        // the projection by hand
        let want = match view {
            View::Iso => [
                (p[0] - p[2]) / 2f64.sqrt(),
                (-p[0] + 2.0 * p[1] - p[2]) / 6f64.sqrt(),
            ],
            _ => [p[0], p[1]],
        };
        let got = body1.projected[1];
        assert!(
            (got[0] - want[0]).abs() < 1e-15 && (got[1] - want[1]).abs() < 1e-15,
            "{scene}: {got:?} vs {want:?}"
        );
        if scene.contains("spatial") {
            // gravity sags the body: the picture is not of the reference
            assert!(p[2] < -1e-6, "S.z = {}", p[2]);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn draw_writes_the_figure_of_a_state_or_a_mode() {
    let dir = temp_dir("draw", "files");
    let scene = fixture("straight_guidance_planar.ron")
        .display()
        .to_string();
    let fig = dir.join("mode2.svg");
    let o = flexmb()
        .args([
            "draw",
            &scene,
            "--mode",
            "2",
            "--phases",
            "3",
            "--reference",
            "--out",
        ])
        .arg(&fig)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("mode 2:") && out.contains("Hz"), "{out}");
    let svg = std::fs::read_to_string(&fig).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("mode 2"),
        "{}",
        &svg[..100]
    );
    // a state file: the first bending deformation of flexure1
    // bent; the drawing differs from the reference one
    let state = dir.join("state.csv");
    std::fs::write(&state, "t,flexure1.1.bending_p\n0,0\n1,0.002\n").unwrap();
    let a = dir.join("state.png");
    let b = dir.join("reference.png");
    for (args, f) in [
        (vec!["--state", &state.display().to_string()], &a),
        (vec![], &b),
    ] {
        let o = flexmb()
            .args(["draw", &scene])
            .args(&args)
            .arg("--out")
            .arg(f)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (a, b) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(&a[..8], b"\x89PNG\r\n\x1a\n");
    assert_ne!(a, b, "the state is not drawn");
    std::fs::remove_dir_all(&dir).ok();
}

/// `--state` takes a `simulate` output file: its DOF columns (`q:NAME`,
/// from `Dofs` among the scene's outputs) fix the configuration, its other
/// output columns (`S.x`, `S.y`) are passed over. A file with only the
/// outputs is an error that says to add `Dofs`, and a column that is
/// neither a DOF nor an output of the scene is an error that names it.
#[test]
fn draw_takes_the_state_from_a_simulate_output_file() {
    let dir = temp_dir("draw", "simulated");
    let text = std::fs::read_to_string(fixture("straight_guidance_planar.ron")).unwrap();
    let with_dofs = text.replace(
        "outputs: [Position(\"S\")]",
        "outputs: [Position(\"S\"), Dofs]",
    );
    assert_ne!(with_dofs, text, "the fixture's outputs changed");
    let draw = |scene: &std::path::Path, state: &std::path::Path, fig: &str| {
        flexmb()
            .args(["draw"])
            .arg(scene)
            .arg("--state")
            .arg(state)
            .arg("--out")
            .arg(dir.join(fig))
            .output()
            .unwrap()
    };
    let mut results = vec![];
    for (name, scene_text) in [("outputs", &text), ("dofs", &with_dofs)] {
        let scene = dir.join(format!("{name}.ron"));
        std::fs::write(&scene, scene_text).unwrap();
        let out = dir.join(name);
        let o = flexmb()
            .args(["simulate"])
            .arg(&scene)
            .args(["--t-end", "0.05", "--outputs", "3", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let csv = out.join("outputs.csv");
        let (header, _) = flexmb_plot::read_csv(&csv).unwrap();
        assert!(header.iter().any(|h| h == "S.x"), "{header:?}");
        results.push((scene, csv, header));
    }
    // only the outputs: no configuration to draw
    let (scene, csv, _) = &results[0];
    let o = draw(scene, csv, "outputs.svg");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("add `Dofs`") && err.contains("S.x"), "{err}");
    // with the DOFs: drawn, and not the reference
    let (scene, csv, header) = &results[1];
    assert!(header.iter().any(|h| h.starts_with("q:")), "{header:?}");
    let o = draw(scene, csv, "dofs.svg");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = flexmb()
        .args(["draw"])
        .arg(scene)
        .arg("--out")
        .arg(dir.join("reference.svg"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let drawn = std::fs::read_to_string(dir.join("dofs.svg")).unwrap();
    let reference = std::fs::read_to_string(dir.join("reference.svg")).unwrap();
    assert_ne!(drawn, reference, "the simulated state is not drawn");
    // a misspelt column is named
    let bad = dir.join("bad.csv");
    let body = std::fs::read_to_string(csv)
        .unwrap()
        .replacen("S.x", "S.xx", 1);
    std::fs::write(&bad, body).unwrap();
    let o = draw(scene, &bad, "bad.svg");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("'S.xx'"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
