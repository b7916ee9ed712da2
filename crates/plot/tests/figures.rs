//! Rendered figures: size and content of the PNG and SVG, markers and lines
//! inside the plot area (from the axis ranges), log ticks at powers of ten,
//! legends holding their whole labels, direct labels beside their points.

use flexmb_plot::{Layout, Plot, Range, Scale, Series, Style, PNG_SCALE};
use std::path::PathBuf;

/// The first eight series colours (the style's palette).
const COLOURS: [[u8; 3]; 8] = [
    [0x00, 0x72, 0xb2],
    [0xd5, 0x5e, 0x00],
    [0x00, 0x9e, 0x73],
    [0xcc, 0x79, 0xa7],
    [0xe6, 0x9f, 0x00],
    [0x56, 0xb4, 0xe9],
    [0x33, 0x33, 0x33],
    [0x8c, 0x56, 0x4b],
];

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-plot-fig-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A speed-against-error plot as the reports draw it: wall time (s) against
/// the largest error (%), log–log, one labelled point per model, some at
/// the extremes of the data.
fn speed_vs_error() -> Plot {
    let pts = [
        ("MODAL-2", 0.021, 41.0),
        ("SVD-7", 0.35, 0.9),
        ("SVD-13", 14.0, 0.012),
        ("MSI-2", 0.019, 12.0),
        ("MSI-7", 0.4, 0.2),
        ("MSI-7g", 0.41, 0.21),
        ("MAC-7", 0.55, 0.05),
        ("Unreduced (generalized-α)", 9.5, 0.08),
    ];
    let mut p = Plot::new(
        "speed against error",
        "wall time of the integration",
        "largest relative error",
    )
    .log_x()
    .log_y()
    .x_unit("s")
    .y_unit("%")
    .without_legend();
    for (n, t, e) in pts {
        p.push(Series::labelled_point(n, t, e));
    }
    p
}

fn lines() -> Plot {
    let x: Vec<f64> = (0..=200)
        .map(|i| -0.0834 + 0.0834 * i as f64 / 100.0)
        .collect();
    let y: Vec<f64> = x.iter().map(|x| 40.0 + 2e3 * x * x).collect();
    let z: Vec<f64> = x.iter().map(|x| 41.0 + 1.9e3 * x * x).collect();
    Plot::new("ω1 over the stroke", "x (m)", "ω1 (Hz)")
        .series(Series::line("Unreduced", &x, &y))
        .series(Series::dashed("SVD-13 with a long label", &x, &z))
        .series(Series::points(
            "samples",
            &[-0.0834, 0.0, 0.0834],
            &[53.9, 40.0, 53.9],
        ))
}

/// The position of `v` along `r` as a fraction, computed here from the
/// range's ends (not from the library's mapping).
fn frac(r: &Range, v: f64) -> f64 {
    match r.scale {
        Scale::Linear => (v - r.lo) / (r.hi - r.lo),
        Scale::Log => (v.log10() - r.lo.log10()) / (r.hi.log10() - r.lo.log10()),
    }
}

fn check_inside(p: &Plot, lay: &Layout) {
    let (pw, ph) = (lay.area.x1 - lay.area.x0, lay.area.y1 - lay.area.y0);
    // markers reach 1.25 r from their centre; lines half their width
    let reach = 1.25 * lay.marker_r + 1.0;
    let mut n = 0;
    for se in p.series_list() {
        for (x, y) in se.x.iter().zip(&se.y) {
            if !(x.is_finite() && y.is_finite()) {
                continue;
            }
            let (fx, fy) = (frac(&lay.x, *x), frac(&lay.y, *y));
            for (f, len, what) in [(fx, pw, "x"), (fy, ph, "y")] {
                assert!(
                    f * len >= reach && (1.0 - f) * len >= reach,
                    "{}: point ({x}, {y}) of {:?} is {:.1} px from the {what} ends of a {len:.0} px axis",
                    se.label,
                    se.style,
                    (f * len).min((1.0 - f) * len)
                );
            }
            n += 1;
        }
    }
    assert!(n > 0);
}

#[test]
fn every_marker_and_line_lies_inside_the_plot_area() {
    for p in [speed_vs_error(), lines()] {
        for scale in [1.0, PNG_SCALE] {
            let lay = p.layout(scale).unwrap();
            check_inside(&p, &lay);
        }
    }
    // a single point, and points on one horizontal line
    let one = Plot::new("one", "x", "y").series(Series::points("a", &[2.0], &[3.0]));
    check_inside(&one, &one.layout(1.0).unwrap());
    let flat = Plot::new("flat", "x", "y").log_y().series(Series::points(
        "a",
        &[1.0, 2.0, 3.0],
        &[5.0, 5.0, 5.0],
    ));
    check_inside(&flat, &flat.layout(1.0).unwrap());
}

#[test]
fn log_ticks_are_at_powers_of_ten_and_read_with_units() {
    let lay = speed_vs_error().layout(1.0).unwrap();
    for (ticks, unit) in [(&lay.x_ticks, " s"), (&lay.y_ticks, " %")] {
        let labelled: Vec<_> = ticks.iter().filter(|t| !t.label.is_empty()).collect();
        assert!(labelled.len() >= 3, "{labelled:?}");
        for t in labelled {
            let e = t.value.log10();
            assert!(
                (e - e.round()).abs() < 1e-12,
                "{} is no power of ten",
                t.value
            );
            assert!(t.label.ends_with(unit), "{}", t.label);
        }
    }
    let xl: Vec<&str> = lay.x_tick_labels.iter().map(|t| t.text.as_str()).collect();
    assert_eq!(xl, ["0.1 s", "1 s", "10 s"]);
    let yl: Vec<&str> = lay.y_tick_labels.iter().map(|t| t.text.as_str()).collect();
    assert_eq!(yl, ["0.01 %", "0.1 %", "1 %", "10 %"]);
    // less than two decades: 2 and 5 as well, all of the form m·10^k
    let p =
        Plot::new("narrow", "t", "e")
            .log_x()
            .series(Series::line("a", &[0.03, 0.9], &[1.0, 2.0]));
    let lay = p.layout(1.0).unwrap();
    let labels: Vec<&str> = lay.x_tick_labels.iter().map(|t| t.text.as_str()).collect();
    assert_eq!(labels, ["0.05", "0.1", "0.2", "0.5"]);
}

#[test]
fn legends_hold_their_whole_labels_and_show_markers_for_points() {
    let p = lines();
    let lay = p.layout(1.0).unwrap();
    let l = lay.legend.as_ref().unwrap();
    assert_eq!(l.entries.len(), 3);
    for (e, se) in l.entries.iter().zip(p.series_list()) {
        assert_eq!(e.text.text, se.label);
        assert!(l.rect.contains(&e.text.rect), "{}", e.text.text);
        assert!(e.text.rect.x1 - e.text.rect.x0 > 5.0 * se.label.chars().count() as f64);
    }
    assert!(l.rect.x1 <= lay.width as f64 && l.rect.y1 <= lay.height as f64);
    assert!(!l.rect.overlaps(&lay.area));
    let svg = p.to_svg().unwrap();
    assert!(svg.contains("\nSVD-13 with a long label\n"));
    // in the PNG: the point series' sample is a marker (coloured centre, white
    // ends), the line series' a line (coloured ends)
    let (lay, rgb) = p.to_rgb().unwrap();
    let l = lay.legend.as_ref().unwrap();
    let at = |x: f64, y: f64| {
        let i = 3 * (y.round() as usize * lay.width as usize + x.round() as usize);
        (rgb[i], rgb[i + 1], rgb[i + 2])
    };
    let white = (255, 255, 255);
    for e in &l.entries {
        let (x0, cy) = e.sample;
        let ends = [at(x0 + 2.0, cy), at(x0 + e.sample_len - 2.0, cy)];
        let mid = at(x0 + e.sample_len / 2.0, cy);
        assert_ne!(mid, white, "{}", e.text.text);
        if p.series_list()[e.series].style == Style::Points {
            assert_eq!(ends, [white; 2], "{}", e.text.text);
        } else {
            assert!(ends.iter().all(|c| *c != white), "{}", e.text.text);
        }
    }
}

#[test]
fn direct_labels_sit_beside_their_points_inside_the_area() {
    let p = speed_vs_error();
    for scale in [1.0, PNG_SCALE] {
        let lay = p.layout(scale).unwrap();
        assert!(lay.legend.is_none());
        assert_eq!(lay.point_labels.len(), p.series_list().len());
        for (k, (i, j, t)) in lay.point_labels.iter().enumerate() {
            let se = &p.series_list()[*i];
            assert_eq!(t.text, se.label);
            assert!(
                lay.area.contains(&t.rect),
                "{} leaves the plot area",
                t.text
            );
            let (px, py) = lay.px(se.x[*j], se.y[*j]).unwrap();
            let d = (t.rect.x0 - px)
                .abs()
                .min((t.rect.x1 - px).abs())
                .min(((t.rect.y0 + t.rect.y1) / 2.0 - py).abs());
            assert!(
                d < 3.0 * lay.marker_r + 20.0 * scale,
                "{} is {d} px from its point",
                t.text
            );
            for (_, _, u) in &lay.point_labels[k + 1..] {
                // MSI-7 and MSI-7g nearly coincide: their labels still must not
                assert!(!t.rect.overlaps(&u.rect), "{} covers {}", t.text, u.text);
            }
        }
    }
}

#[test]
fn png_and_svg_have_the_laid_out_size_and_show_the_data() {
    let dir = tmp("save");
    let p = speed_vs_error();
    let (svg, png) = p.save_both(&dir.join("speed_vs_error.svg")).unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&bytes[12..16], b"IHDR");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    let lay = p.layout(PNG_SCALE).unwrap();
    assert_eq!((w, h), (lay.width, lay.height));
    assert!(w >= 1200 && h >= 750, "{w} x {h}");
    let text = std::fs::read_to_string(&svg).unwrap();
    let lay1 = p.layout(1.0).unwrap();
    assert!(
        text.contains(&format!("width=\"{}\"", lay1.width)),
        "{}",
        &text[..200]
    );
    for se in p.series_list() {
        let escaped = se.label.replace('&', "&amp;");
        assert!(text.contains(&escaped), "{} missing in the SVG", se.label);
    }
    // a marker at every point, and every series' colour in the pixels
    // (MSI-7 covers the centre of MSI-7g's marker)
    let (lay, rgb) = p.to_rgb().unwrap();
    assert_eq!(rgb.len(), 3 * (lay.width * lay.height) as usize);
    let non_white = rgb.chunks(3).filter(|c| c != &[255, 255, 255]).count();
    let frac = non_white as f64 / (lay.width * lay.height) as f64;
    assert!(
        (0.01..0.5).contains(&frac),
        "{frac} of the pixels are drawn"
    );
    let mut colours = std::collections::HashSet::new();
    for se in p.series_list() {
        let (x, y) = lay.px(se.x[0], se.y[0]).unwrap();
        let i = 3 * (y.round() as usize * lay.width as usize + x.round() as usize);
        assert_ne!(
            &rgb[i..i + 3],
            &[255, 255, 255],
            "{} has no marker",
            se.label
        );
    }
    for c in rgb.chunks(3) {
        colours.insert(c.to_vec());
    }
    for k in 0..p.series_list().len() {
        assert!(
            colours.contains(COLOURS[k].as_slice()),
            "colour of series {k} missing"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn wrong_paths_and_empty_data_give_errors_or_empty_figures_not_panics() {
    let dir = tmp("bad");
    let p = lines();
    let e = p.save(&dir.join("fig.pdf")).unwrap_err().to_string();
    assert!(e.contains("fig.pdf") && e.contains(".svg or .png"), "{e}");
    let e = p
        .save(&dir.join("no/such/dir/fig.png"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("fig.png"), "{e}");
    // nothing a log axis can show, NaN only, and no series at all
    let odd = [
        Plot::new("neg", "x", "y")
            .log_y()
            .series(Series::line("a", &[1.0, 2.0], &[-1.0, 0.0])),
        Plot::new("nan", "x", "y").series(Series::points("a", &[f64::NAN], &[1.0])),
        Plot::new("none", "x", "y"),
    ];
    for p in odd {
        let svg = p.to_svg().unwrap();
        assert!(svg.contains("</svg>"));
        let (lay, _) = p.to_rgb().unwrap();
        assert!(lay.x.lo < lay.x.hi && lay.y.lo < lay.y.hi);
    }
    std::fs::remove_dir_all(&dir).ok();
}
