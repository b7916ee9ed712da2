//! The planar layout of the two-DOF mechanism of thesis chapter 4 (Figs
//! 4.2–4.3): where each cross-hinge's rotation axis is, which members it
//! joins, and where the members' boundary nodes are.
//!
//! The CAD of the mechanism is lost; what the text keeps is its topology and
//! the dimensions of Tables 4.1–4.3. The layout here is a documented
//! substitute (docs/reproduce.md, "Chapter 4"):
//!
//! * two parallelograms: the base – UpperArmX1 – CrossBar – UpperArmX2 loop,
//!   which lets the CrossBar translate (mostly in x), and the CrossBar's
//!   elbows – LowerArmX1 – end-effector – LowerArmX2 loop, which lets the
//!   end-effector translate relative to it (mostly in y); the spacing vector
//!   d of both is at 135° so that neither parallelogram is degenerate (d not
//!   parallel to any arm);
//! * the actuator arm UpperArmY – LowerArmY from the base to the
//!   end-effector: with the X arms a five-bar linkage B1–E1–F1–F3–E3–B3 that
//!   fixes the end-effector's position from the two upper-arm angles;
//! * all hinge axes along global z; the mechanism's mid-plane z = 0, the
//!   sheets of the five-sheet hinges stacked symmetrically about it (their
//!   heights of Table 4.3 and 1 mm gaps make 87 mm, the mechanism's height);
//! * the member superelements from boundary node to boundary node with
//!   exactly the lengths of Table 4.1: a hinge's boundary nodes sit on the
//!   axes of the members it joins, (L/2) cos 45° from its rotation axis (the
//!   mean location of the sheet ends clamped to that member), so the
//!   hinge-to-hinge distance of a member is its Table 4.1 length plus those
//!   two offsets.

/// A point or vector in the mechanism plane or in space (m).
pub type V3 = [f64; 3];

/// a + s b.
pub fn add(a: V3, s: f64, b: V3) -> V3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

/// b − a.
pub fn sub(b: V3, a: V3) -> V3 {
    [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
}

/// |a|.
pub fn norm(a: V3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// a / |a|.
pub fn unit(a: V3) -> V3 {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// a × b.
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The in-plane vector `a` turned about z by `deg` degrees.
pub fn turned(a: V3, deg: f64) -> V3 {
    let (s, c) = deg.to_radians().sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1], a[2]]
}

/// Global z, the axis of every hinge.
pub const Z: V3 = [0.0, 0.0, 1.0];

/// The kinds of five-sheet cross-hinges of Table 4.3 and the wire–sheet
/// hinge of Table 4.2.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HingeKind {
    /// At the base (UpperArmX1, UpperArmX2, UpperArmY).
    Base,
    /// Between UpperArmX1/X2 and LowerArmX1/X2.
    ElbowX,
    /// Between UpperArmY and LowerArmY.
    ElbowY,
    /// Between the lower arms and the end-effector.
    EndEffector,
    /// A wire and a sheet, between the upper X arms and the CrossBar.
    WireSheet,
}

/// Table 4.3 (five-sheet hinges) and Table 4.2 (wire–sheet): the sheets'
/// length, thickness, and the heights of the main, outer and cross sheets
/// (m). The wire–sheet hinge's "main" sheet is its one sheet; it has no
/// outer or cross sheet (its wire: [`WIRE_LENGTH`], [`WIRE_DIAMETER`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sheets {
    /// Flexure length L.
    pub length: f64,
    /// Flexure thickness t.
    pub thickness: f64,
    /// Main flexure height.
    pub main: f64,
    /// Outer flexure height (0 for the wire–sheet hinge).
    pub outer: f64,
    /// Cross flexure height (0 for the wire–sheet hinge).
    pub cross: f64,
}

impl HingeKind {
    /// The flexure dimensions of Tables 4.2 and 4.3.
    pub fn sheets(self) -> Sheets {
        let mm = 1e-3;
        let (length, thickness, main, outer, cross) = match self {
            HingeKind::Base => (50.0, 0.5, 33.0, 10.0, 15.0),
            HingeKind::ElbowX => (40.0, 0.4, 38.0, 8.0, 7.0),
            HingeKind::ElbowY => (40.0, 0.4, 43.0, 10.0, 10.0),
            HingeKind::EndEffector => (35.0, 0.3, 14.0, 4.0, 3.0),
            HingeKind::WireSheet => (20.0, 0.3, 14.0, 0.0, 0.0),
        };
        Sheets {
            length: length * mm,
            thickness: thickness * mm,
            main: main * mm,
            outer: outer * mm,
            cross: cross * mm,
        }
    }

    /// Whether the main sheet is 3 superelements with warping modes (thesis
    /// §4.2.2: the elbows' main sheets, h/l = 0.95 and 1.075, and the
    /// CrossBar hinges' sheets, h/l = 0.7) rather than 3 beams.
    pub fn main_as_superelements(self) -> bool {
        matches!(
            self,
            HingeKind::ElbowX | HingeKind::ElbowY | HingeKind::WireSheet
        )
    }

    /// The distance from the rotation axis to each boundary node: (L/2)
    /// cos 45°, the mean location of the sheet ends on one side.
    pub fn attachment_offset(self) -> f64 {
        0.5 * self.sheets().length * std::f64::consts::FRAC_1_SQRT_2
    }

    /// Short name for ids.
    pub fn tag(self) -> &'static str {
        match self {
            HingeKind::Base => "base",
            HingeKind::ElbowX => "elbow_x",
            HingeKind::ElbowY => "elbow_y",
            HingeKind::EndEffector => "ee",
            HingeKind::WireSheet => "wire_sheet",
        }
    }
}

/// Wire length of the wire–sheet hinge (m), Table 4.2.
pub const WIRE_LENGTH: f64 = 20e-3;
/// Wire diameter (m), Table 4.2.
pub const WIRE_DIAMETER: f64 = 0.4e-3;
/// The gap between stacked sheets, and between the wire–sheet hinge's sheet
/// and its wire (m): with Table 4.3's base hinge, 33 + 2 (15 + 10) + 4 × 1 =
/// 87 mm, the mechanism's height.
pub const SHEET_GAP: f64 = 1e-3;

/// The members of Table 4.1 with their superelement lengths (m).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Member {
    /// UpperArmX1 (carries the x-actuator coils and an encoder).
    UpperArmX1,
    /// UpperArmX2.
    UpperArmX2,
    /// UpperArmY (carries the y-actuator coils and an encoder).
    UpperArmY,
    /// LowerArmX1 (torsion and out-of-plane bending releases).
    LowerArmX1,
    /// LowerArmX2 (the same releases).
    LowerArmX2,
    /// LowerArmY (the same releases, and an encoder).
    LowerArmY,
    /// CrossBar (steel, out-of-plane bending releases at both ends).
    CrossBar,
    /// The end-effector (a rigid superelement).
    EndEffector,
}

impl Member {
    /// Every member, in the order of Table 4.1.
    pub const ALL: [Member; 8] = [
        Member::UpperArmX1,
        Member::UpperArmX2,
        Member::UpperArmY,
        Member::LowerArmX1,
        Member::LowerArmX2,
        Member::LowerArmY,
        Member::CrossBar,
        Member::EndEffector,
    ];

    /// The superelement length of Table 4.1 (m): the distance between its
    /// boundary nodes.
    pub fn length(self) -> f64 {
        1e-3 * match self {
            Member::UpperArmX1 | Member::UpperArmX2 => 330.8,
            Member::UpperArmY => 240.9,
            Member::LowerArmX1 | Member::LowerArmX2 => 232.1,
            Member::LowerArmY => 267.4,
            Member::CrossBar | Member::EndEffector => 153.9,
        }
    }

    /// The solid-element count of the thesis's Ansys model (Table 4.1).
    pub fn thesis_elements(self) -> usize {
        match self {
            Member::UpperArmX1 | Member::UpperArmX2 => 32316,
            Member::UpperArmY => 22702,
            Member::LowerArmX1 | Member::LowerArmX2 => 9893,
            Member::LowerArmY => 11887,
            Member::CrossBar => 5736,
            Member::EndEffector => 13476,
        }
    }

    /// The thesis's name.
    pub fn name(self) -> &'static str {
        match self {
            Member::UpperArmX1 => "UpperArmX1",
            Member::UpperArmX2 => "UpperArmX2",
            Member::UpperArmY => "UpperArmY",
            Member::LowerArmX1 => "LowerArmX1",
            Member::LowerArmX2 => "LowerArmX2",
            Member::LowerArmY => "LowerArmY",
            Member::CrossBar => "CrossBar",
            Member::EndEffector => "EndEffector",
        }
    }

    /// Whether its FE model has the torsion (T-profile) and out-of-plane
    /// bending (notch) releases of thesis §4.1.3.
    pub fn has_arm_releases(self) -> bool {
        matches!(
            self,
            Member::LowerArmX1 | Member::LowerArmX2 | Member::LowerArmY
        )
    }
}

/// One cross-hinge: its rotation axis (through `axis_point`, along z), the
/// directions of the members it joins (`u_in` of the member on its A side,
/// `u_out` of the one on its B side), and its boundary nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct Hinge {
    /// Id (also the prefix of its nodes and elements).
    pub id: &'static str,
    /// Kind (Tables 4.2, 4.3).
    pub kind: HingeKind,
    /// A point of its rotation axis, in the mid-plane z = 0.
    pub axis_point: V3,
    /// Direction of the member on its A side, pointing towards the hinge.
    pub u_in: V3,
    /// Direction of the member on its B side, pointing away from the hinge.
    pub u_out: V3,
}

impl Hinge {
    /// The boundary node on the A side: (L/2) cos 45° back along `u_in`.
    pub fn node_a(&self) -> V3 {
        add(self.axis_point, -self.kind.attachment_offset(), self.u_in)
    }

    /// The boundary node on the B side: (L/2) cos 45° on along `u_out`.
    pub fn node_b(&self) -> V3 {
        add(self.axis_point, self.kind.attachment_offset(), self.u_out)
    }

    /// The in-plane directions of its two sheet planes, crossing at 90° on
    /// the axis. A five-sheet hinge: ±45° about the bisector of `u_in` and
    /// `u_out`, the first holding the main and outer sheets, the second the
    /// cross sheets. A wire–sheet hinge: the sheet along the CrossBar, the
    /// wire across it, so that the sheet's torsion lets the CrossBar twist
    /// about its axis (thesis §4.1.3, Fig. 4.5).
    pub fn sheet_directions(&self) -> (V3, V3) {
        let b = unit(add(self.u_in, 1.0, self.u_out));
        match self.kind {
            HingeKind::WireSheet => (b, turned(b, 90.0)),
            _ => (turned(b, 45.0), turned(b, -45.0)),
        }
    }
}

/// The mechanism's layout: the eleven hinges and where each member runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// The hinges, in the order base X1, X2, Y; elbows X1, X2, Y; end-effector
    /// X1, X2, Y; CrossBar 1, 2.
    pub hinges: Vec<Hinge>,
    /// The spacing vector d of both parallelograms (m).
    pub d: V3,
}

/// The distance between the axes of the two hinges at the ends of a member:
/// its Table 4.1 length plus both hinges' attachment offsets.
fn axis_distance(m: Member, a: HingeKind, b: HingeKind) -> f64 {
    m.length() + a.attachment_offset() + b.attachment_offset()
}

/// Where the LowerArmY's end-effector hinge axis sits from LowerArmX1's (m),
/// chosen so that the two base hinges B1 and B3 are 72 mm apart.
pub const F3_FROM_F1: V3 = [0.080, -0.040, 0.0];

/// Where the CrossBar's hinge axes sit from the elbow hinge axes of the X
/// arms, back along the upper arms (m).
pub const CROSSBAR_BELOW_ELBOW: f64 = 0.040;

impl Layout {
    /// The substitute layout (module docs): base hinge X1 at the origin,
    /// UpperArmX1 along +y, LowerArmX1 along +x, d at 135°, UpperArmY along
    /// +x, LowerArmY along +y.
    pub fn new() -> Self {
        use HingeKind::*;
        let (ex, ey) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // CrossBar: 153.9 mm between its boundary nodes, each a wire–sheet
        // attachment offset inside its hinge axis; the same spacing for the
        // end-effector's parallelogram
        let spacing = Member::CrossBar.length() + 2.0 * WireSheet.attachment_offset();
        let d = [
            -spacing * std::f64::consts::FRAC_1_SQRT_2,
            spacing * std::f64::consts::FRAC_1_SQRT_2,
            0.0,
        ];
        let b1 = [0.0; 3];
        let e1 = add(b1, axis_distance(Member::UpperArmX1, Base, ElbowX), ey);
        let f1 = add(
            e1,
            axis_distance(Member::LowerArmX1, ElbowX, EndEffector),
            ex,
        );
        let (b2, e2, f2) = (add(b1, 1.0, d), add(e1, 1.0, d), add(f1, 1.0, d));
        let f3 = add(f1, 1.0, F3_FROM_F1);
        let e3 = add(
            f3,
            -axis_distance(Member::LowerArmY, ElbowY, EndEffector),
            ey,
        );
        let b3 = add(e3, -axis_distance(Member::UpperArmY, Base, ElbowY), ex);
        let c1 = add(e1, -CROSSBAR_BELOW_ELBOW, ey);
        let c2 = add(c1, 1.0, d);
        let du = unit(d);
        let h = |id, kind, at, u_in, u_out| Hinge {
            id,
            kind,
            axis_point: at,
            u_in,
            u_out,
        };
        Layout {
            hinges: vec![
                h("hb_x1", Base, b1, ey, ey),
                h("hb_x2", Base, b2, ey, ey),
                h("hb_y", Base, b3, ex, ex),
                h("he_x1", ElbowX, e1, ey, ex),
                h("he_x2", ElbowX, e2, ey, ex),
                h("he_y", ElbowY, e3, ex, ey),
                h("hf_x1", EndEffector, f1, ex, ex),
                h("hf_x2", EndEffector, f2, ex, ex),
                h("hf_y", EndEffector, f3, ey, ey),
                h("hc_1", WireSheet, c1, du, du),
                h("hc_2", WireSheet, c2, du, du),
            ],
            d,
        }
    }

    /// The hinge `id`.
    pub fn hinge(&self, id: &str) -> &Hinge {
        self.hinges
            .iter()
            .find(|h| h.id == id)
            .unwrap_or_else(|| panic!("no hinge {id}"))
    }

    /// The member superelements: (member, p, q) with p and q their boundary
    /// nodes, the hinges' B and A nodes (the CrossBar's between its two
    /// hinges, the end-effector's from LowerArmX1's end-effector hinge along
    /// d). UpperArmX2 and LowerArmX2 are their X1 twins moved by d.
    pub fn members(&self) -> Vec<(Member, V3, V3)> {
        let b = |id: &str| self.hinge(id).node_b();
        let a = |id: &str| self.hinge(id).node_a();
        let ee_p = b("hf_x1");
        vec![
            (Member::UpperArmX1, b("hb_x1"), a("he_x1")),
            (Member::UpperArmX2, b("hb_x2"), a("he_x2")),
            (Member::UpperArmY, b("hb_y"), a("he_y")),
            (Member::LowerArmX1, b("he_x1"), a("hf_x1")),
            (Member::LowerArmX2, b("he_x2"), a("hf_x2")),
            (Member::LowerArmY, b("he_y"), a("hf_y")),
            (Member::CrossBar, b("hc_1"), a("hc_2")),
            (
                Member::EndEffector,
                ee_p,
                add(ee_p, Member::EndEffector.length(), unit(self.d)),
            ),
        ]
    }

    /// The footprint of the hinge axes: (min, max) corners in the plane (m).
    pub fn extent(&self) -> (V3, V3) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for h in &self.hinges {
            for k in 0..3 {
                lo[k] = lo[k].min(h.axis_point[k]);
                hi[k] = hi[k].max(h.axis_point[k]);
            }
        }
        (lo, hi)
    }
}

impl Default for Layout {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every member superelement spans exactly its Table 4.1 length between
    /// its boundary nodes, and both parallelograms close: the X2 hinges are
    /// the X1 hinges moved by d, and the CrossBar's hinges are d apart.
    #[test]
    fn members_have_the_table_lengths_and_the_parallelograms_close() {
        let l = Layout::new();
        for (m, p, q) in l.members() {
            let len = norm(sub(q, p));
            assert!(
                (len - m.length()).abs() < 1e-12,
                "{}: {len} against {}",
                m.name(),
                m.length()
            );
        }
        for (a, b) in [
            ("hb_x1", "hb_x2"),
            ("he_x1", "he_x2"),
            ("hf_x1", "hf_x2"),
            ("hc_1", "hc_2"),
        ] {
            let gap = sub(l.hinge(b).axis_point, l.hinge(a).axis_point);
            assert!(norm(sub(gap, l.d)) < 1e-12, "{a}–{b}: {gap:?}");
        }
        // the X arms' parallelogram sides are not parallel to d
        let du = unit(l.d);
        for u in [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]] {
            assert!(norm(cross(du, u)) > 0.5);
        }
        // the five-sheet hinges stack to the mechanism's 87 mm
        let s = HingeKind::Base.sheets();
        let stack = s.main + 2.0 * (s.outer + s.cross) + 4.0 * SHEET_GAP;
        assert!((stack - 0.087).abs() < 1e-12, "{stack}");
    }

    /// Each hinge's boundary nodes are on the members' axes and its sheet
    /// planes cross at 90° on the axis; a wire–sheet hinge's sheet is along
    /// the CrossBar.
    #[test]
    fn hinge_nodes_and_sheets_are_placed_symmetrically() {
        let l = Layout::new();
        for h in &l.hinges {
            let (s1, s2) = h.sheet_directions();
            let dot = s1[0] * s2[0] + s1[1] * s2[1];
            assert!(dot.abs() < 1e-12, "{}", h.id);
            if h.kind == HingeKind::WireSheet {
                assert!(
                    norm(sub(s1, unit(l.d))) < 1e-12,
                    "{}: the sheet along the CrossBar",
                    h.id
                );
            }
            let c = h.kind.attachment_offset();
            assert!((norm(sub(h.node_a(), h.axis_point)) - c).abs() < 1e-15);
            assert!((norm(sub(h.node_b(), h.axis_point)) - c).abs() < 1e-15);
        }
    }
}
