//! The scene of the chapter-4 mechanism (thesis §4.2, Fig. 4.6) as RON
//! text, from the [`Layout`]: the member superelements between the hinges'
//! boundary nodes, each cross-hinge as its sheets (3 beams each, or 3
//! superelements with warping for the main sheets of the elbows and of the
//! CrossBar hinges) clamped by rigid beams to the boundary nodes on either
//! side (Fig. 4.11; the wires of the CrossBar hinges as trusses,
//! [`SceneText::wire`]), the CrossBar joined to the upper X arms by rigid beams
//! (Fig. 4.10), and the end-effector a rigid superelement with a massless
//! rigid beam to its third hinge (Fig. 4.7).
//!
//! Also the kinematic skeleton of §4.1.3 ([`skeleton`]): rigid members and
//! ideal hinges, with or without the releases, for the constraint diagnosis.

use super::layout::{
    add, cross, sub, unit, Hinge, HingeKind, Layout, Member, SHEET_GAP, V3, WIRE_DIAMETER,
    WIRE_LENGTH, Z,
};
use std::collections::BTreeMap;
use std::fmt::Write;

/// Beams per flexure (thesis §4.2.2: three beams, or three superelements).
pub const PER_SHEET: usize = 3;

/// The file of a member's superelement, relative to the scene.
pub fn member_file(m: Member) -> String {
    let stem = match m {
        // LowerArmX1 and LowerArmX2 are the same part, parallel
        Member::LowerArmX1 | Member::LowerArmX2 => "lower_arm_x",
        Member::UpperArmX1 => "upper_arm_x1",
        Member::UpperArmX2 => "upper_arm_x2",
        Member::UpperArmY => "upper_arm_y",
        Member::LowerArmY => "lower_arm_y",
        Member::CrossBar => "crossbar",
        Member::EndEffector => "end_effector",
    };
    format!("{DIR}/{stem}.se.ron")
}

/// The file of the superelement of a third of the main sheet of the hinges
/// `kind` (its direction is the same in the two X elbows and in the two
/// CrossBar hinges).
pub fn sheet_file(kind: HingeKind) -> String {
    format!("{DIR}/{}_sheet.se.ron", kind.tag())
}

/// The directory of the part files, next to the scene.
pub const DIR: &str = "two_dof_mechanism";

/// The node at the end-effector whose x and y follow the path (4.1): the
/// end-effector's side of LowerArmX1's end-effector hinge, the
/// end-effector superelement's node p.
pub const END_EFFECTOR_NODE: &str = "hf_x1.B";

fn v(a: V3) -> String {
    // exact (shortest round-trip), rounding-level noise of the layout's
    // turns shown as 0
    let r = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
    format!("[{:?}, {:?}, {:?}]", r(a[0]), r(a[1]), r(a[2]))
}

/// A scene under construction, as RON pieces.
#[derive(Default)]
pub struct SceneText {
    nodes: Vec<String>,
    elements: Vec<String>,
    rigid: Vec<String>,
    fixed: Vec<String>,
    sections: BTreeMap<String, String>,
    /// Node positions, to place the rigid beams.
    at: BTreeMap<String, V3>,
}

impl SceneText {
    /// A node at `at`.
    pub fn node(&mut self, id: &str, at: V3) {
        self.nodes.push(format!(r#"(id: "{id}", at: {})"#, v(at)));
        self.at.insert(id.into(), at);
    }

    /// A node with the position of `of` and an orientation of its own.
    pub fn node_sharing(&mut self, id: &str, of: &str) {
        self.nodes
            .push(format!(r#"(id: "{id}", position_of: Some("{of}"))"#));
        let p = self.at[of];
        self.at.insert(id.into(), p);
    }

    fn position(&self, id: &str) -> V3 {
        self.at[id]
    }

    /// A section.
    pub fn section(&mut self, id: &str, text: &str) {
        self.sections.insert(id.into(), text.into());
    }

    /// A flexible beam chain of `n` from `p` to `q` (steel, section `sec`,
    /// local y along `up`), every deformation flexible: with the
    /// elongations free the model has the thesis's 688 degrees of freedom
    /// (with beams for the wires), and three coplanar sheets of a hinge with
    /// rigid elongations would over-constrain it (three parallel length
    /// constraints in one plane have rank two).
    pub fn flexure(&mut self, id: &str, p: &str, q: &str, sec: &str, up: V3, n: usize) {
        self.elements.push(format!(
            r#"(id: "{id}", type: Beam((nodes: ("{p}", "{q}"), material: "steel", section: "{sec}", up: Some({}), n: {n})))"#,
            v(up)
        ));
    }

    /// A wire flexure from `p` to `q` as one truss (steel, Table 4.2's
    /// diameter): its axial constraint, without the bending stiffness of the
    /// thesis's three beams, which is four orders of magnitude below the
    /// sheet's next to it (EI/L = 0.013 N m against 130 N m) and whose
    /// near-singular bending and torsion DOFs made the static Newton
    /// iteration along the path take 2–4× the iterations (measured: 26–48
    /// against 15–29 per point).
    pub fn wire(&mut self, id: &str, p: &str, q: &str) {
        let area = std::f64::consts::PI * 0.25 * WIRE_DIAMETER * WIRE_DIAMETER;
        let (e, rho) = (2.1e11, 7800.0);
        self.elements.push(format!(
            r#"(id: "{id}", type: Truss(nodes: ("{p}", "{q}"), ea: {:?}, mass_per_length: {:?}))"#,
            e * area,
            rho * area
        ));
    }

    /// A massless rigid beam from `p` to `q`: a rigid interconnection of the
    /// SPACAR model.
    pub fn rigid_beam(&mut self, id: &str, p: &str, q: &str) {
        let d = sub(self.position(q), self.position(p));
        let up = if cross(unit(d), Z).iter().map(|c| c.abs()).sum::<f64>() > 1e-3 {
            Z
        } else {
            [1.0, 0.0, 0.0]
        };
        self.elements.push(format!(
            r#"(id: "{id}", type: Beam((nodes: ("{p}", "{q}"), material: "steel", section: "rigid", up: Some({}), mass: false)))"#,
            v(up)
        ));
        self.rigid.push(format!(r#"Def("{id}", "*")"#));
    }

    /// A superelement.
    pub fn superelement(
        &mut self,
        id: &str,
        p: &str,
        q: &str,
        file: &str,
        share: Option<(&str, &str)>,
    ) {
        let share = match share {
            Some((a, b)) => format!(r#", share: (Some("{a}"), Some("{b}"))"#),
            None => String::new(),
        };
        self.elements.push(format!(
            r#"(id: "{id}", type: Superelement(nodes: ("{p}", "{q}"), file: "{file}", transform: B3{share}))"#
        ));
    }

    /// A spatial hinge element about `axis` between the orientations of `p`
    /// and `q`; its bending deformations rigid (an ideal revolute joint)
    /// when `ideal`.
    pub fn hinge(&mut self, id: &str, p: &str, q: &str, axis: V3, ideal: bool) {
        self.elements.push(format!(
            r#"(id: "{id}", type: Hinge(nodes: ("{p}", "{q}"), axis: Some({})))"#,
            v(axis)
        ));
        if ideal {
            self.rigid.push(format!(r#"Def("{id}", "bending_y")"#));
            self.rigid.push(format!(r#"Def("{id}", "bending_z")"#));
        }
    }

    /// Adds a raw element entry.
    pub fn element(&mut self, text: String) {
        self.elements.push(text);
    }

    /// Fixes a node, or a mode group.
    pub fn fix(&mut self, what: String) {
        self.fixed.push(what);
    }

    /// Makes a deformation rigid.
    pub fn make_rigid(&mut self, what: String) {
        self.rigid.push(what);
    }

    /// The scene text.
    pub fn finish(&self, name: &str, tail: &str) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "(\n    name: \"{name}\",\n    dimension: Spatial,");
        let _ = writeln!(
            s,
            "    materials: {{ \"steel\": (e: 2.1e11, g: Some(8.0e10), rho: 7800.0) }},"
        );
        let _ = writeln!(s, "    sections: {{");
        for (k, t) in &self.sections {
            let _ = writeln!(s, "        \"{k}\": {t},");
        }
        let _ = writeln!(s, "    }},\n    nodes: [");
        for n in &self.nodes {
            let _ = writeln!(s, "        {n},");
        }
        let _ = writeln!(s, "    ],\n    elements: [");
        for e in &self.elements {
            let _ = writeln!(s, "        {e},");
        }
        let _ = writeln!(s, "    ],\n    fixed: [");
        for f in &self.fixed {
            let _ = writeln!(s, "        {f},");
        }
        let _ = writeln!(s, "    ],\n    rigid: [");
        for r in &self.rigid {
            let _ = writeln!(s, "        {r},");
        }
        let _ = writeln!(s, "    ],\n{tail})");
        s
    }
}

/// The ids of a hinge's two boundary nodes.
pub fn boundary_nodes(h: &Hinge) -> (String, String) {
    (format!("{}.A", h.id), format!("{}.B", h.id))
}

/// One sheet of a hinge: its plane direction, the z of its mid-height, its
/// height and section id, and whether it is the main sheet.
struct SheetPlace {
    tag: String,
    dir: V3,
    z: f64,
    height: f64,
    main: bool,
}

/// The sheets of a five-sheet hinge (Table 4.3), stacked in z: outer, cross,
/// main, cross, outer with [`SHEET_GAP`] between them; main and outer in the
/// first plane, the cross sheets in the second.
fn five_sheets(h: &Hinge) -> Vec<SheetPlace> {
    let s = h.kind.sheets();
    let (d1, d2) = h.sheet_directions();
    let zc = 0.5 * s.main + SHEET_GAP + 0.5 * s.cross;
    let zo = 0.5 * s.main + SHEET_GAP + s.cross + SHEET_GAP + 0.5 * s.outer;
    let sheet = |tag: &str, dir, z, height, main| SheetPlace {
        tag: tag.into(),
        dir,
        z,
        height,
        main,
    };
    vec![
        sheet("main", d1, 0.0, s.main, true),
        sheet("cross_up", d2, zc, s.cross, false),
        sheet("cross_down", d2, -zc, s.cross, false),
        sheet("outer_up", d1, zo, s.outer, false),
        sheet("outer_down", d1, -zo, s.outer, false),
    ]
}

/// The section ids of a hinge kind's sheets.
fn sheet_section(kind: HingeKind, height_tag: &str) -> String {
    format!("{}_{height_tag}", kind.tag())
}

/// Adds the sections every hinge kind needs.
pub fn hinge_sections(st: &mut SceneText) {
    for kind in [
        HingeKind::Base,
        HingeKind::ElbowX,
        HingeKind::ElbowY,
        HingeKind::EndEffector,
    ] {
        let s = kind.sheets();
        for (tag, h) in [("main", s.main), ("outer", s.outer), ("cross", s.cross)] {
            st.section(
                &sheet_section(kind, tag),
                &format!("Rectangle(by: {h:?}, bz: {:?})", s.thickness),
            );
        }
    }
    st.section("rigid", "Rectangle(by: 0.01, bz: 0.01)");
}

/// A main sheet as three superelements with warping, shared at the inner
/// interfaces and restrained at both clamped ends (thesis §3.5.1, §4.2.2).
fn sheet_superelements(st: &mut SceneText, id: &str, a: &str, b: &str, kind: HingeKind) {
    let (pa, pb) = (st.position(a), st.position(b));
    let file = sheet_file(kind);
    let mut prev = a.to_string();
    for k in 0..PER_SHEET {
        let next = if k + 1 == PER_SHEET {
            b.to_string()
        } else {
            let n = format!("{id}.n{}", k + 1);
            st.node(&n, add(pa, (k + 1) as f64 / PER_SHEET as f64, sub(pb, pa)));
            n
        };
        let (w0, w1) = (format!("{id}.w{k}"), format!("{id}.w{}", k + 1));
        st.superelement(
            &format!("{id}.{}", k + 1),
            &prev,
            &next,
            &file,
            Some((&w0, &w1)),
        );
        prev = next;
    }
    st.fix(format!(r#"Modes("{id}.w0")"#));
    st.fix(format!(r#"Modes("{id}.w{PER_SHEET}")"#));
}

/// One hinge of the full model: its boundary nodes, its sheets (and the
/// wire of a wire–sheet hinge) from clamp to clamp, and the rigid beams
/// clamping them to the boundary nodes.
pub fn add_hinge(st: &mut SceneText, h: &Hinge) {
    let (na, nb) = boundary_nodes(h);
    st.node(&na, h.node_a());
    st.node(&nb, h.node_b());
    let s = h.kind.sheets();
    let half = 0.5 * s.length;
    let place = |st: &mut SceneText, tag: &str, dir: V3, z: f64, kind: Flexure| {
        let base = [h.axis_point[0], h.axis_point[1], z];
        let (ea, eb) = (format!("{}.{tag}.a", h.id), format!("{}.{tag}.b", h.id));
        let len = match kind {
            Flexure::Wire => 0.5 * WIRE_LENGTH,
            _ => half,
        };
        st.node(&ea, add(base, -len, dir));
        st.node(&eb, add(base, len, dir));
        let id = format!("{}.{tag}", h.id);
        match kind {
            Flexure::Beams(sec) => st.flexure(&id, &ea, &eb, &sec, Z, PER_SHEET),
            Flexure::Superelements => sheet_superelements(st, &id, &ea, &eb, h.kind),
            Flexure::Wire => st.wire(&id, &ea, &eb),
        }
        st.rigid_beam(&format!("{}.{tag}.clamp_a", h.id), &na, &ea);
        st.rigid_beam(&format!("{}.{tag}.clamp_b", h.id), &eb, &nb);
    };
    if h.kind == HingeKind::WireSheet {
        let (d1, d2) = h.sheet_directions();
        place(st, "sheet", d1, 0.0, Flexure::Superelements);
        let zw = 0.5 * s.main + SHEET_GAP + 0.5 * WIRE_DIAMETER;
        place(st, "wire", d2, zw, Flexure::Wire);
        return;
    }
    for sh in five_sheets(h) {
        let kind = if sh.main && h.kind.main_as_superelements() {
            Flexure::Superelements
        } else {
            let tag = if sh.main {
                "main"
            } else if sh.tag.starts_with("cross") {
                "cross"
            } else {
                "outer"
            };
            debug_assert!(sh.height > 0.0);
            Flexure::Beams(sheet_section(h.kind, tag))
        };
        place(st, &sh.tag, sh.dir, sh.z, kind);
    }
}

/// How a flexure is modelled.
enum Flexure {
    /// Three beams of this section.
    Beams(String),
    /// Three superelements with warping.
    Superelements,
    /// The wire: one truss ([`SceneText::wire`]).
    Wire,
}

/// The full scene (thesis Fig. 4.6) without outputs, loads or gravity
/// (chapter 4 leaves gravity out of the eigenvalue analyses): the text, to be
/// written as `two_dof_mechanism.ron` next to the part files of [`DIR`].
pub fn full_scene(layout: &Layout) -> String {
    scene_text(layout, false)
}

/// The actuator hinges of thesis §7.2.1 and their ground nodes: (hinge,
/// ground node, the base hinge whose B node is the arm's first node).
pub const ACTUATORS: [(&str, &str, &str); 2] = [
    ("act_x", "act_x.ground", "hb_x1"),
    ("act_y", "act_y.ground", "hb_y"),
];

/// The full scene with the actuator hinges of chapter 7 (§7.2.1): between
/// the fixed world and UpperArmX1, and between it and UpperArmY, axes along
/// z, at the arms' base hinge axes, with zero stiffness and their bending
/// deformations free, so that they neither stiffen nor constrain the arm;
/// their rotations `act_x.rotation` and `act_y.rotation` are the
/// co-located sensors φx, φy, and the PD controllers (7.12) act on them.
pub fn actuated_scene(layout: &Layout) -> String {
    scene_text(layout, true)
}

fn scene_text(layout: &Layout, actuated: bool) -> String {
    let mut st = SceneText::default();
    if actuated {
        for (hinge, ground, base) in ACTUATORS {
            st.node(ground, layout.hinge(base).axis_point);
            st.fix(format!(r#"Node("{ground}")"#));
            st.element(format!(
                r#"(id: "{hinge}", type: Hinge(nodes: ("{ground}", "{base}.B"), axis: Some({}), stiffness: 0.0, bending_stiffness: 0.0))"#,
                v(Z)
            ));
        }
    }
    hinge_sections(&mut st);
    for h in &layout.hinges {
        add_hinge(&mut st, h);
    }
    // the ground side of the base hinges
    for id in ["hb_x1", "hb_x2", "hb_y"] {
        st.fix(format!(r#"Node("{id}.A")"#));
    }
    let node = |id: &str, b: bool| format!("{id}.{}", if b { "B" } else { "A" });
    // members: from a hinge's B node to the next one's A node
    let ends: [(Member, &str, &str); 6] = [
        (Member::UpperArmX1, "hb_x1", "he_x1"),
        (Member::UpperArmX2, "hb_x2", "he_x2"),
        (Member::UpperArmY, "hb_y", "he_y"),
        (Member::LowerArmX1, "he_x1", "hf_x1"),
        (Member::LowerArmX2, "he_x2", "hf_x2"),
        (Member::LowerArmY, "he_y", "hf_y"),
    ];
    for (m, from, to) in ends {
        st.superelement(
            m.name(),
            &node(from, true),
            &node(to, false),
            &member_file(m),
            None,
        );
    }
    // the CrossBar between its hinges, joined to the upper X arms' ends by
    // rigid beams (Fig. 4.10)
    st.superelement(
        Member::CrossBar.name(),
        &node("hc_1", true),
        &node("hc_2", false),
        &member_file(Member::CrossBar),
        None,
    );
    st.rigid_beam(
        "crossbar_link_1",
        &node("he_x1", false),
        &node("hc_1", false),
    );
    st.rigid_beam(
        "crossbar_link_2",
        &node("hc_2", true),
        &node("he_x2", false),
    );
    // the end-effector: a rigid superelement from LowerArmX1's end-effector
    // hinge along d, a rigid beam on to LowerArmX2's and one to LowerArmY's
    let ee = Member::EndEffector;
    let p = layout.hinge("hf_x1").node_b();
    let q = add(p, ee.length(), unit(layout.d));
    st.node("EE.q", q);
    st.superelement(ee.name(), END_EFFECTOR_NODE, "EE.q", &member_file(ee), None);
    st.make_rigid(format!(r#"Def("{}", "*")"#, ee.name()));
    st.rigid_beam("ee_link_x2", "EE.q", &node("hf_x2", true));
    st.rigid_beam("ee_link_y", END_EFFECTOR_NODE, &node("hf_y", true));
    st.finish(
        if actuated {
            "Two-DOF large-stroke compliant mechanism with the actuator hinges of thesis ch. 7 (§7.2.1)"
        } else {
            "Two-DOF large-stroke compliant mechanism, a substitute of thesis ch. 4 (Fig. 4.6)"
        },
        &format!("    dofs: Deformations,\n    outputs: [Position(\"{END_EFFECTOR_NODE}\")],\n"),
    )
}

/// Which releases of thesis §4.1.3 a [`skeleton`] has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Releases {
    /// The lower arms' torsion (T-profile) and out-of-plane bending
    /// (notch) releases.
    pub lower_arms: bool,
    /// The CrossBar's notches and the torsion of its wire–sheet hinges.
    pub crossbar: bool,
}

impl Releases {
    /// Every release: exactly constrained.
    pub const ALL: Releases = Releases {
        lower_arms: true,
        crossbar: true,
    };
    /// None: nine times over-constrained.
    pub const NONE: Releases = Releases {
        lower_arms: false,
        crossbar: false,
    };
}

/// The kinematic skeleton of thesis §4.1.3: rigid members (rigid beams
/// between the hinge axes) and ideal revolute cross-hinges about z; with
/// `releases.lower_arms`, the lower arms' torsion and out-of-plane bending
/// releases (ideal hinges about the arm and about the in-plane normal, at
/// 85 % of the arm); with `releases.crossbar`, the CrossBar's notches and
/// wire–sheet hinges (at each end a hinge about z, one about the sheet's
/// direction and one about the in-plane normal: a spherical joint). Without
/// releases it is nine times over-constrained; with all of them exactly
/// constrained with mobility 3: the two DOFs and the CrossBar's twist.
pub fn skeleton(layout: &Layout, releases: Releases) -> String {
    let mut st = SceneText::default();
    st.section("rigid", "Rectangle(by: 0.01, bz: 0.01)");
    let at = |id: &str| layout.hinge(id).axis_point;
    // each hinge: a node on each side, sharing the position
    for h in &layout.hinges {
        st.node(&format!("{}.A", h.id), h.axis_point);
        st.node_sharing(&format!("{}.B", h.id), &format!("{}.A", h.id));
    }
    for id in ["hb_x1", "hb_x2", "hb_y"] {
        st.fix(format!(r#"Node("{id}.A")"#));
    }
    let joint = |st: &mut SceneText, id: &str, a: &str, b: &str, axis: V3| {
        st.hinge(id, a, b, axis, true);
    };
    for h in &layout.hinges {
        if h.kind == HingeKind::WireSheet && releases.crossbar {
            // z, then the sheet's direction, then the in-plane normal to
            // the CrossBar (the notch), through intermediate nodes
            let (s1, _) = h.sheet_directions();
            let n = cross(Z, unit(layout.d));
            let (a, m1, m2, b) = (
                format!("{}.A", h.id),
                format!("{}.m1", h.id),
                format!("{}.m2", h.id),
                format!("{}.B", h.id),
            );
            st.node_sharing(&m1, &a);
            st.node_sharing(&m2, &a);
            joint(&mut st, &format!("{}.z", h.id), &a, &m1, Z);
            joint(&mut st, &format!("{}.sheet", h.id), &m1, &m2, s1);
            joint(&mut st, &format!("{}.notch", h.id), &m2, &b, n);
        } else {
            joint(
                &mut st,
                h.id,
                &format!("{}.A", h.id),
                &format!("{}.B", h.id),
                Z,
            );
        }
    }
    let link = |st: &mut SceneText, id: &str, p: &str, q: &str| st.rigid_beam(id, p, q);
    link(&mut st, "UpperArmX1", "hb_x1.B", "he_x1.A");
    link(&mut st, "UpperArmX2", "hb_x2.B", "he_x2.A");
    link(&mut st, "UpperArmY", "hb_y.B", "he_y.A");
    link(&mut st, "crossbar_link_1", "he_x1.A", "hc_1.A");
    link(&mut st, "crossbar_link_2", "he_x2.A", "hc_2.B");
    link(&mut st, "CrossBar", "hc_1.B", "hc_2.A");
    for (arm, from, to) in [
        ("LowerArmX1", "he_x1", "hf_x1"),
        ("LowerArmX2", "he_x2", "hf_x2"),
        ("LowerArmY", "he_y", "hf_y"),
    ] {
        let (a, b) = (format!("{from}.B"), format!("{to}.A"));
        if releases.lower_arms {
            let u = unit(sub(at(to), at(from)));
            let r = add(at(from), 0.85, sub(at(to), at(from)));
            let (r0, r1, r2) = (
                format!("{arm}.r0"),
                format!("{arm}.r1"),
                format!("{arm}.r2"),
            );
            st.node(&r0, r);
            st.node_sharing(&r1, &r0);
            st.node_sharing(&r2, &r0);
            link(&mut st, &format!("{arm}.in"), &a, &r0);
            joint(&mut st, &format!("{arm}.torsion"), &r0, &r1, u);
            joint(&mut st, &format!("{arm}.notch"), &r1, &r2, cross(Z, u));
            link(&mut st, &format!("{arm}.out"), &r2, &b);
        } else {
            link(&mut st, arm, &a, &b);
        }
    }
    // the end-effector: rigid beams between its three hinges
    link(&mut st, "EndEffector", "hf_x1.B", "hf_x2.B");
    link(&mut st, "EndEffector_y", "hf_x1.B", "hf_y.B");
    st.finish(
        match (releases.lower_arms, releases.crossbar) {
            (true, true) => {
                "Kinematic skeleton of the ch. 4 mechanism, with the releases of §4.1.3"
            }
            (false, false) => "Kinematic skeleton of the ch. 4 mechanism, without releases",
            (true, false) => "Kinematic skeleton of the ch. 4 mechanism, lower-arm releases only",
            (false, true) => "Kinematic skeleton of the ch. 4 mechanism, CrossBar releases only",
        },
        "",
    )
}
