//! gmsh meshes read by `mesh_file` against gmsh's own Abaqus writer (an
//! independent conversion of its node orders): one `.geo` of each element
//! kind gmsh makes with second-order elements (10-node tetrahedra, 20-node
//! hexahedra from a recombined extrusion, 15-node wedges from an extruded
//! triangle mesh) saved as `.msh` (4.1 and 2.2) and as `.inp`; the elements,
//! read from the `.msh` and turned into the Abaqus order, must be those of
//! the `.inp` node for node, and the physical surface's nodes those of
//! gmsh's node set. Needs `gmsh`; fails, never skips, without it.

use flexmb_superelement::geometry::SolidKind;
use flexmb_superelement::mesh_file::{read_msh, MeshFile};
use flexmb_superelement::readers::read_inp;
use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

fn gmsh(dir: &Path, geo: &str, args: &[&str]) {
    let o = Command::new("gmsh")
        .arg(geo)
        .args([
            "-3",
            "-order",
            "2",
            "-setnumber",
            "Mesh.SecondOrderIncomplete",
            "1",
        ])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("gmsh is not on PATH: apt-get install gmsh");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

const EXTRUDE: &str = "Point(1) = {0, 0, 0, 0.5};\nPoint(2) = {2, 0, 0, 0.5};\nPoint(3) = {2, 1, 0, 0.5};\n\
Point(4) = {0, 1, 0, 0.5};\nLine(1) = {1, 2};\nLine(2) = {2, 3};\nLine(3) = {3, 4};\nLine(4) = {4, 1};\n\
Curve Loop(1) = {1, 2, 3, 4};\nPlane Surface(1) = {1};\n";

#[test]
fn msh_elements_in_abaqus_order_are_gmsh_inp_elements() {
    let dir = std::env::temp_dir().join(format!("flexmb-gmsh-meshes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            "tet",
            "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 2, 1, 0.5};\nMesh.CharacteristicLengthMax = 0.5;\n\
             Physical Volume(\"PART\") = {1};\nPhysical Surface(\"end\") = {1};\n"
                .to_string(),
            SolidKind::Tet10,
        ),
        (
            "hex",
            format!(
                "{EXTRUDE}Transfinite Surface{{1}};\nRecombine Surface{{1}};\n\
                 out[] = Extrude {{0, 0, 0.5}} {{ Surface{{1}}; Layers{{2}}; Recombine; }};\n\
                 Physical Volume(\"PART\") = {{out[1]}};\nPhysical Surface(\"end\") = {{out[5]}};\n"
            ),
            SolidKind::Hex20,
        ),
        (
            "wedge",
            format!(
                "{EXTRUDE}out[] = Extrude {{0, 0, 0.5}} {{ Surface{{1}}; Layers{{2}}; Recombine; }};\n\
                 Physical Volume(\"PART\") = {{out[1]}};\nPhysical Surface(\"end\") = {{out[5]}};\n"
            ),
            SolidKind::Wedge15,
        ),
    ];
    for (name, geo, kind) in cases {
        std::fs::write(dir.join(format!("{name}.geo")), geo).unwrap();
        let g = format!("{name}.geo");
        gmsh(
            &dir,
            &g,
            &["-format", "msh41", "-o", &format!("{name}.msh")],
        );
        gmsh(
            &dir,
            &g,
            &["-format", "msh22", "-o", &format!("{name}22.msh")],
        );
        gmsh(
            &dir,
            &g,
            &[
                "-setnumber",
                "Mesh.SaveGroupsOfNodes",
                "1",
                "-format",
                "inp",
                "-o",
                &format!("{name}.inp"),
            ],
        );
        let inp = read_inp(&dir.join(format!("{name}.inp"))).unwrap();
        let expected: HashMap<u64, Vec<u64>> = inp
            .elements
            .iter()
            .zip(&inp.element_ids)
            .filter(|((ty, _), _)| SolidKind::from_type(ty) == Some(kind))
            .map(|((_, nodes), &id)| (id, nodes.clone()))
            .collect();
        assert!(!expected.is_empty(), "{name}: gmsh wrote no {kind:?}");
        for file in [format!("{name}.msh"), format!("{name}22.msh")] {
            let mesh: MeshFile = read_msh(&dir.join(&file)).unwrap();
            assert!(
                mesh.kinds.iter().all(|k| *k == kind),
                "{file}: {}",
                mesh.describe_elements()
            );
            assert_eq!(mesh.elements.len(), expected.len(), "{file}");
            for (e, &id) in mesh.elements.iter().zip(&mesh.element_ids) {
                let labels: Vec<u64> = e.iter().map(|&i| mesh.ids[i]).collect();
                assert_eq!(Some(&labels), expected.get(&id), "{file}: element {id}");
            }
            // the physical surface's nodes: gmsh's node set of it
            let group = mesh
                .groups
                .iter()
                .find(|g| g.name == "end")
                .expect("the surface");
            let mut ours: Vec<u64> = group.nodes.iter().map(|&i| mesh.ids[i]).collect();
            ours.sort_unstable();
            let mut theirs = inp.nsets.get("END").cloned().expect("gmsh's node set END");
            theirs.sort_unstable();
            theirs.dedup();
            assert_eq!(ours, theirs, "{file}: the nodes of 'end'");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
