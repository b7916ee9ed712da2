//! Every type in the workspace that derives `Deserialize` (they all read user
//! input: scenes, superelement specs and files, saved reduced models) also
//! denies unknown fields, and none uses `untagged` or `flatten`, with which
//! serde's `deny_unknown_fields` silently does nothing.

use std::path::{Path, PathBuf};

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn every_deserialize_derive_denies_unknown_fields() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = vec![];
    for c in std::fs::read_dir(&crates).unwrap() {
        let src = c.unwrap().path().join("src");
        if src.is_dir() {
            sources(&src, &mut files);
        }
    }
    let (mut checked, mut missing, mut loose) = (0, vec![], vec![]);
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            let t = l.trim_start();
            if t.starts_with("#[serde(") && (t.contains("untagged") || t.contains("flatten")) {
                loose.push(format!("{}:{}", f.display(), i + 1));
            }
            if !(t.starts_with("#[derive(") && t.contains("Deserialize")) {
                continue;
            }
            // the attributes between the derive and the item
            let mut j = i + 1;
            let mut denies = false;
            while j < lines.len() && lines[j].trim_start().starts_with("#[") {
                denies |= lines[j].contains("deny_unknown_fields");
                j += 1;
            }
            let item = lines.get(j).copied().unwrap_or("");
            // a tuple struct has no field names to misspell
            let tuple = item.contains("struct") && item.contains('(');
            if !denies && !tuple {
                missing.push(format!("{}:{}: {}", f.display(), j + 1, item.trim()));
            }
            checked += 1;
        }
    }
    assert!(checked >= 35, "only {checked} Deserialize derives found");
    assert!(
        missing.is_empty(),
        "add #[serde(deny_unknown_fields)] to: {missing:#?}"
    );
    assert!(
        loose.is_empty(),
        "untagged/flatten defeat deny_unknown_fields: {loose:#?}"
    );
}
