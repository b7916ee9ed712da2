//! The strict reader: unknown fields and variants rejected at every level
//! with line, column and the nearest valid name; repeated map keys rejected.

use flexmb_input::{edit_distance, from_ron, nearest, unique_keys};
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};

#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct Inner {
    tolerance: f64,
}

#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
enum Shape {
    Circle { d: f64 },
    Wrapped(Inner),
    Unit,
}

#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct Outer {
    #[serde(default)]
    gravity: Option<Vec<f64>>,
    #[serde(default, deserialize_with = "unique_keys")]
    by_name: BTreeMap<String, Shape>,
    #[serde(default, deserialize_with = "unique_keys")]
    hashed: HashMap<String, f64>,
}

#[test]
fn nearest_names_a_likely_typo_only() {
    assert_eq!(edit_distance("gravityy", "gravity"), 1);
    assert_eq!(edit_distance("", "abc"), 3);
    assert_eq!(edit_distance("kitten", "sitting"), 3);
    let fields = ["name", "gravity", "materials", "fixed"];
    assert_eq!(nearest("gravityy", fields), Some("gravity"));
    assert_eq!(nearest("fixd", fields), Some("fixed"));
    assert_eq!(nearest("elements", fields), None);
    // a short name is not "corrected" into an unrelated one
    assert_eq!(nearest("ab", ["xy", "a"]), Some("a"));
    assert_eq!(nearest("q", ["pq"]), Some("pq"));
    assert_eq!(nearest("xyz", ["abc"]), None);
    // works on Strings too
    let ids = vec!["C".to_string(), "B".to_string()];
    assert_eq!(nearest("CC", &ids), Some("C"));
}

#[test]
fn unknown_fields_are_refused_at_every_level() {
    let ok: Outer = from_ron(
        r#"(gravity: [0.0, -9.81], by_name: { "a": Circle(d: 1.0), "b": Wrapped((tolerance: 1.0)), "c": Unit })"#,
    )
    .unwrap();
    assert_eq!(ok.by_name.len(), 3);
    // implicit Some
    let ok: Outer = from_ron("(gravity: [1.0])").unwrap();
    assert_eq!(ok.gravity, Some(vec![1.0]));
    for (text, line, column, field, suggestion) in [
        (
            "(\n  gravityy: [1.0],\n)",
            2,
            3,
            "`gravityy`",
            Some("gravity"),
        ),
        (
            "(by_name: {\n \"a\": Circle(dd: 1.0) })",
            2,
            14,
            "`dd`",
            Some("d"),
        ),
        (
            "(by_name: {\n \"a\": Wrapped((tolerence: 1.0)) })",
            2,
            16,
            "`tolerence`",
            Some("tolerance"),
        ),
        (
            "(by_name: { \"a\": Circel(d: 1.0) })",
            1,
            18,
            "`Circel`",
            Some("Circle"),
        ),
        ("(zzz: 1)", 1, 2, "`zzz`", None),
    ] {
        let e = from_ron::<Outer>(text).unwrap_err();
        assert_eq!((e.line, e.column), (line, column), "{text}: {e}");
        assert!(e.message.contains(field), "{e}");
        match suggestion {
            Some(s) => assert!(e.message.ends_with(&format!("did you mean `{s}`?")), "{e}"),
            None => assert!(!e.message.contains("did you mean"), "{e}"),
        }
    }
}

#[test]
fn repeated_map_keys_are_refused_naming_the_key() {
    let e =
        from_ron::<Outer>("(by_name: {\n \"a\": Unit,\n \"a\": Circle(d: 1.0),\n})").unwrap_err();
    assert_eq!(e.line, 3, "{e}");
    assert!(e.message.contains("duplicate key 'a'"), "{e}");
    let e = from_ron::<Outer>(r#"(hashed: { "x": 1.0, "y": 2.0, "x": 3.0 })"#).unwrap_err();
    assert!(e.message.contains("duplicate key 'x'"), "{e}");
    let ok = from_ron::<Outer>(r#"(hashed: { "x": 1.0, "y": 2.0 })"#).unwrap();
    assert_eq!(ok.hashed["y"], 2.0);
}
