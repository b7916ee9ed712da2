//! Pictures of the straight guidances: the figure files, the plot area, and
//! mode shapes checked against the eigenvector.

use flexmb_draw::{
    geometry, mode_shape, node_positions, picture, Configuration, DrawOptions, ItemKind, Picture,
    Style, View,
};
use flexmb_kinematics::Kinematics;
use flexmb_model::{Mechanism, Scene};
use flexmb_plot::{Layout, PNG_SCALE};
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn mechanism(name: &str) -> Arc<Mechanism> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/scenes")
        .join(name);
    let scene = Scene::load(&p).unwrap();
    Arc::new(scene.build(p.parent()).unwrap())
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-draw-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every point of every series lies inside the plot area with the marker
/// around it (markers) or on it (lines): from the axis ranges, not pixels.
fn check_inside(pic: &Picture, lay: &Layout) {
    let plot = pic.plot();
    let a = lay.area;
    let mut n = 0;
    for (layer, it) in pic
        .layers
        .iter()
        .flat_map(|l| l.geometry.items.iter().map(move |i| (l, i)))
    {
        if it.kind.is_marker() && !layer.markers {
            continue;
        }
        let r = if it.kind.is_marker() {
            1.25 * lay.marker_r
        } else {
            0.0
        };
        for p in &it.projected {
            let fx = (p[0] - lay.x.lo) / (lay.x.hi - lay.x.lo);
            let fy = (p[1] - lay.y.lo) / (lay.y.hi - lay.y.lo);
            let (px, py) = (a.x0 + fx * (a.x1 - a.x0), a.y1 - fy * (a.y1 - a.y0));
            assert!(
                px - r > a.x0 && px + r < a.x1 && py - r > a.y0 && py + r < a.y1,
                "{:?} of {} at ({px}, {py}) outside {a:?} in '{}'",
                it.kind,
                it.id,
                pic.title
            );
            n += 1;
        }
    }
    assert!(n > 10, "{n} points");
    // one data unit is as long on both axes
    let ux = (lay.x.hi - lay.x.lo) / (a.x1 - a.x0);
    let uy = (lay.y.hi - lay.y.lo) / (a.y1 - a.y0);
    assert!((ux / uy - 1.0).abs() < 0.02, "aspect {ux} vs {uy}");
    assert!(!plot.series_list().is_empty());
}

#[test]
fn every_drawn_item_lies_inside_the_plot_area() {
    let planar = mechanism("straight_guidance_planar.ron");
    let spatial = mechanism("straight_guidance_spatial.ron");
    let cases = [
        (
            &planar,
            DrawOptions {
                reference: true,
                ..Default::default()
            },
        ),
        (
            &planar,
            DrawOptions {
                mode: Some(1),
                phases: Some(3),
                ..Default::default()
            },
        ),
        (
            &spatial,
            DrawOptions {
                mode: Some(2),
                phases: Some(2),
                ..Default::default()
            },
        ),
        (
            &spatial,
            DrawOptions {
                view: Some(View::Xz),
                reference: true,
                ..Default::default()
            },
        ),
    ];
    for (mech, opts) in cases {
        let at = Configuration::static_equilibrium(mech).unwrap();
        let pic = picture(&at, &opts).unwrap();
        for s in [1.0, PNG_SCALE] {
            check_inside(&pic, &pic.plot().layout(s).unwrap());
        }
    }
}

#[test]
fn png_and_svg_have_the_laid_out_size_and_show_the_elements() {
    let mech = mechanism("straight_guidance_planar.ron");
    let at = Configuration::reference(&mech).unwrap();
    let pic = picture(&at, &DrawOptions::default()).unwrap();
    let dir = tmp("files");
    let svg = dir.join("guidance.svg");
    let png = dir.join("guidance.png");
    pic.save(&svg).unwrap();
    pic.save(&png).unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    let lay = pic.plot().layout(PNG_SCALE).unwrap();
    assert_eq!((w, h), (lay.width, lay.height));
    // the SVG: its size, a path for the beams, a marker per fixed node
    let text = std::fs::read_to_string(&svg).unwrap();
    let lay1 = pic.plot().layout(1.0).unwrap();
    assert!(text.contains(&format!("width=\"{}\"", lay1.width)));
    assert!(text.contains("beams") && text.contains("fixed nodes"));
    let fixed = pic.layers[0]
        .geometry
        .items
        .iter()
        .filter(|i| i.kind == ItemKind::FixedNode)
        .count();
    assert_eq!(fixed, 2, "A and C are fixed");
    // the beam colour (#0072B2) is drawn on the segment from A (0, 0) to
    // B (0, 0.2), midway
    let (lay, rgb) = pic.plot().to_rgb().unwrap();
    let (x, y) = lay.px(0.0, 0.1).unwrap();
    let i = 3 * (y.round() as usize * lay.width as usize + x.round() as usize);
    assert_eq!(&rgb[i..i + 3], &[0x00, 0x72, 0xb2], "no beam at ({x}, {y})");
    // the fixed node A carries its own marker colour (#333333), not the
    // palette's for a second series
    let (x, y) = lay.px(0.0, 0.0).unwrap();
    let i = 3 * (y.round() as usize * lay.width as usize + x.round() as usize);
    assert_eq!(&rgb[i..i + 3], &[0x33, 0x33, 0x33], "no ground marker at A");
    let drawn = rgb.chunks(3).filter(|c| c != &[255, 255, 255]).count();
    assert!(drawn > 1000, "{drawn} pixels drawn");
    // nothing but white at the middle of the empty span between the flexures
    let (x, y) = lay.px(0.1, 0.1).unwrap();
    let i = 3 * (y.round() as usize * lay.width as usize + x.round() as usize);
    assert!(
        rgb[i..i + 3].iter().all(|c| *c > 200),
        "{:?}",
        &rgb[i..i + 3]
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The nodal displacement d = F,q v by central differences of the position
/// solve (independent of the library's F,ξ).
fn displacement_by_differences(mech: &Arc<Mechanism>, q: &[f64], v: &[f64]) -> Vec<f64> {
    let h = 1e-6;
    let mut kin = Kinematics::new(mech.clone());
    let mut at = |s: f64| {
        let qs: Vec<f64> = q.iter().zip(v).map(|(a, b)| a + s * b).collect();
        kin.solve(&qs, 0.0).unwrap();
        kin.x().to_vec()
    };
    let (p, m) = (at(h), at(-h));
    p.iter().zip(&m).map(|(a, b)| (a - b) / (2.0 * h)).collect()
}

#[test]
fn a_mode_shape_is_the_eigenvector_scaled_to_the_amplitude() {
    for (scene, k) in [
        ("straight_guidance_planar.ron", 2),
        ("straight_guidance_spatial.ron", 1),
    ] {
        let mech = mechanism(scene);
        let at = Configuration::static_equilibrium(&mech).unwrap();
        // the eigenvector as `flexmb eig --static-first` computes it
        let mut dy = flexmb_dynamics::Dynamics::new(at.mechanism.clone());
        dy.kinematics_mut().set_guess(&at.x);
        let lin = dy.linearize_at_rest(0.0, &at.q).unwrap();
        let modes = flexmb_linearize::undamped_modes(&lin, k).unwrap();
        let v: Vec<f64> = (0..mech.n_dof())
            .map(|i| modes.vectors[(i, k - 1)])
            .collect();
        let shape = mode_shape(&at, k).unwrap();
        assert_eq!(shape.q, v);
        assert_eq!(shape.frequency_hz, modes.frequencies_hz()[k - 1]);
        let d = displacement_by_differences(&at.mechanism, &at.q, &v);
        let amplitude = 0.004;
        let pic = picture(
            &at,
            &DrawOptions {
                mode: Some(k),
                amplitude: Some(amplitude),
                phases: Some(3),
                // every drawn point a node (tests/outline.rs: the boxes)
                style: Style::Lines,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(pic.title.contains(&format!("mode {k}")), "{}", pic.title);
        let f = format!("{:.1}", shape.frequency_hz);
        assert!(pic.title.contains(&f[..f.len() - 2]), "{}", pic.title);
        // layers: at rest, then the phases +1, 0, -1
        assert_eq!(pic.layers.len(), 4);
        let rest = node_positions(&at.mechanism, &at.x);
        let largest = at
            .mechanism
            .nodes
            .iter()
            .map(|n| n.position.iter().map(|i| d[*i].powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        let scale = amplitude / largest;
        for (layer, factor) in pic.layers[1..].iter().zip([1.0, 0.0, -1.0]) {
            let mut biggest: f64 = 0.0;
            // each segment's end points are nodes: compare them with rest + f·scale·d
            let rest_items = geometry(&at.mechanism, &at.x, pic.view).items;
            for (it, r) in layer.geometry.items.iter().zip(&rest_items) {
                assert_eq!(it.id, r.id);
                for (p, p0) in it.model.iter().zip(&r.model) {
                    let node = rest
                        .iter()
                        .position(|q| q == p0)
                        .expect("a drawn point is a node");
                    let n = &at.mechanism.nodes[node];
                    let mut len2 = 0.0;
                    for (c, i) in n.position.iter().enumerate() {
                        let want = p0[c] + factor * scale * d[*i];
                        assert!(
                            (p[c] - want).abs() < 1e-6 * amplitude,
                            "{scene} mode {k} node {} component {c}: {} vs {want}",
                            n.id,
                            p[c]
                        );
                        len2 += (p[c] - p0[c]).powi(2);
                    }
                    biggest = biggest.max(len2.sqrt());
                }
            }
            assert!(
                (biggest - factor.abs() * amplitude).abs() < 1e-6 * amplitude,
                "{scene}: largest displacement {biggest}, amplitude {amplitude}"
            );
        }
    }
}

#[test]
fn the_default_amplitude_is_a_tenth_of_the_size_and_bad_options_are_refused() {
    let mech = mechanism("straight_guidance_planar.ron");
    let at = Configuration::reference(&mech).unwrap();
    let pic = picture(
        &at,
        &DrawOptions {
            mode: Some(1),
            style: Style::Lines,
            ..Default::default()
        },
    )
    .unwrap();
    let size = pic.layers[0].geometry.size();
    // the box around the guidance's nodes: 0.2 × 0.2 m
    assert!((size - 0.2 * 2f64.sqrt()).abs() < 1e-12, "{size}");
    let (shape, scale) = pic.mode.as_ref().unwrap();
    let a = scale * shape.largest_nodal_displacement(&at.mechanism);
    assert!((a - 0.1 * size).abs() < 1e-12 * size, "{a}");
    let e = picture(
        &at,
        &DrawOptions {
            mode: Some(18),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("18") && e.contains("17 modes"), "{e}");
    let e = picture(
        &at,
        &DrawOptions {
            mode: Some(1),
            amplitude: Some(-1.0),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("amplitude") && e.contains("-1"), "{e}");
}

/// The position of node `id` in the configuration `x`.
fn node_at(mech: &Mechanism, x: &[f64], id: &str) -> [f64; 3] {
    let k = mech.nodes.iter().position(|n| n.id == id).unwrap();
    node_positions(mech, x)[k]
}

/// The items of `kind` of element (or node) `id`.
fn items_of<'a>(
    g: &'a flexmb_draw::Geometry,
    kind: ItemKind,
    id: &str,
) -> Vec<&'a flexmb_draw::Item> {
    g.items
        .iter()
        .filter(|i| i.kind == kind && i.id == id)
        .collect()
}

#[test]
fn hinges_masses_and_superelements_are_drawn_at_their_nodes() {
    // the manipulator: hinges G–O and E1–E2, point masses at E1 and T, G fixed
    let man = mechanism("manipulator_planar.ron");
    let x = &man.x0;
    let g = geometry(&man, x, View::Xy);
    for (kind, id, node) in [
        (ItemKind::Hinge, "joint1", "G"),
        (ItemKind::Hinge, "joint2", "E1"),
        (ItemKind::PointMass, "m1", "E1"),
        (ItemKind::PointMass, "m2", "T"),
        (ItemKind::FixedNode, "G", "G"),
    ] {
        let it = items_of(&g, kind, id);
        assert_eq!(it.len(), 1, "{kind:?} {id}");
        assert_eq!(it[0].model, vec![node_at(&man, x, node)], "{kind:?} {id}");
    }
    // four beams per link, each a segment
    let beams = g.items.iter().filter(|i| i.kind == ItemKind::Beam).count();
    assert_eq!(beams, 8);
    // superelements: the dashed chord between the interface nodes, and a
    // marker at each
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fuzz/superelement_chain.ron");
    let scene = Scene::load(&p).unwrap();
    let se = Arc::new(scene.build(p.parent()).unwrap());
    let at = Configuration::static_equilibrium(&se).unwrap();
    let g = geometry(&se, &at.x, View::Iso);
    for (id, a, b) in [("se1", "P", "M"), ("se2", "M", "Q")] {
        let chord = items_of(&g, ItemKind::SuperelementChord, id);
        assert_eq!(chord.len(), 1, "{id}");
        let (pa, pb) = (node_at(&se, &at.x, a), node_at(&se, &at.x, b));
        assert_eq!(chord[0].model, vec![pa, pb], "{id}");
        let ends: Vec<[f64; 3]> = items_of(&g, ItemKind::InterfaceNode, id)
            .iter()
            .map(|i| i.model[0])
            .collect();
        assert_eq!(ends, vec![pa, pb], "{id}");
    }
    // the tip load and gravity moved Q off the reference
    let q = node_at(&se, &at.x, "Q");
    assert!(q[1] > 1e-9 && q[2] < -1e-9, "Q at {q:?}");
    assert_eq!(items_of(&g, ItemKind::PointMass, "tip")[0].model, vec![q]);
}
