//! Strict reading of flexmb's RON input files: scenes, superelement build
//! specifications, superelement files and saved reduced models.
//!
//! A typo in an input file must not change the model silently. Every
//! user-facing type derives `Deserialize` with `#[serde(deny_unknown_fields)]`
//! (so `gravityy: ..` is an error, not a scene without gravity); this crate
//! turns the parser's errors into messages with line, column and the nearest
//! valid name, and gives maps that reject a repeated key instead of keeping
//! the last entry.
//!
//! ```
//! use serde::Deserialize;
//! #[derive(Debug, Deserialize)]
//! #[serde(deny_unknown_fields)]
//! struct Settings {
//!     #[serde(default)]
//!     gravity: Option<f64>,
//! }
//! let e = flexmb_input::from_ron::<Settings>("(\n  gravityy: 9.81,\n)").unwrap_err();
//! assert_eq!((e.line, e.column), (2, 3));
//! assert!(e.message.contains("did you mean `gravity`?"), "{e}");
//! ```
#![warn(missing_docs)]

use serde::de::{DeserializeOwned, Deserializer, Error as _, MapAccess, Visitor};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use std::marker::PhantomData;

/// The Levenshtein distance between two strings (in characters).
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let c = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + c);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The candidate nearest to `name` by edit distance, if it is near enough to
/// be a likely typo: at most 3 edits, and at most 1 + half the length of
/// `name` (so a short name is not "corrected" into an unrelated one). Ties
/// go to the first candidate.
pub fn nearest<'a, I, S>(name: &str, candidates: I) -> Option<&'a str>
where
    I: IntoIterator<Item = &'a S>,
    S: AsRef<str> + ?Sized + 'a,
{
    let limit = 3.min(1 + name.chars().count() / 2);
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        let c = c.as_ref();
        let d = edit_distance(name, c);
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// A RON error located in its text: 1-based line and column, and a message
/// that for an unknown field or variant ends with the nearest valid name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Located {
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Located {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "line {}, column {}: {}",
            self.line, self.column, self.message
        )
    }
}

impl std::error::Error for Located {}

/// Describes a RON error: where it is and what is wrong, with "did you mean
/// `x`?" for an unknown field or enum variant that is a likely typo of a
/// valid one.
pub fn describe(e: &ron::error::SpannedError) -> Located {
    let mut message = e.code.to_string();
    let suggestion = match &e.code {
        ron::Error::NoSuchStructField {
            expected, found, ..
        }
        | ron::Error::NoSuchEnumVariant {
            expected, found, ..
        } => nearest(found, expected.iter().copied()),
        _ => None,
    };
    if let Some(s) = suggestion {
        message.push_str(&format!("; did you mean `{s}`?"));
    }
    Located {
        line: e.span.start.line,
        column: e.span.start.col,
        message,
    }
}

/// Parses RON text into `T` (with `Some(..)` optional around optional values),
/// the errors described by [`describe`].
pub fn from_ron<T: DeserializeOwned>(text: &str) -> Result<T, Located> {
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
        .from_str(text)
        .map_err(|e| describe(&e))
}

/// Deserializes a map that rejects a repeated key, naming it, instead of
/// keeping the last entry. For any map field whose keys are `Ord` and
/// `Display`: `#[serde(deserialize_with = "flexmb_input::unique_keys")]`, or
/// through [`unique_keys_named`] to say what the keys are.
pub fn unique_keys<'de, D, K, V, M>(d: D) -> Result<M, D::Error>
where
    D: Deserializer<'de>,
    K: Deserialize<'de> + Ord + fmt::Display,
    V: Deserialize<'de>,
    M: FromIterator<(K, V)>,
{
    unique_keys_named(d, "key")
}

/// [`unique_keys`] with the kind of key for the message: `what` =
/// `"material id"` gives "duplicate material id 'steel'".
pub fn unique_keys_named<'de, D, K, V, M>(d: D, what: &'static str) -> Result<M, D::Error>
where
    D: Deserializer<'de>,
    K: Deserialize<'de> + Ord + fmt::Display,
    V: Deserialize<'de>,
    M: FromIterator<(K, V)>,
{
    struct Unique<K, V> {
        what: &'static str,
        _kv: PhantomData<(K, V)>,
    }
    impl<'de, K, V> Visitor<'de> for Unique<K, V>
    where
        K: Deserialize<'de> + Ord + fmt::Display,
        V: Deserialize<'de>,
    {
        type Value = BTreeMap<K, V>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "a map with each {} once", self.what)
        }
        fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Self::Value, A::Error> {
            let mut map = BTreeMap::new();
            while let Some(k) = a.next_key::<K>()? {
                if map.contains_key(&k) {
                    return Err(A::Error::custom(format!(
                        "duplicate {} '{k}' (each may appear once; the later entry would replace the earlier one)",
                        self.what
                    )));
                }
                let v = a.next_value()?;
                map.insert(k, v);
            }
            Ok(map)
        }
    }
    let map = d.deserialize_map(Unique {
        what,
        _kv: PhantomData,
    })?;
    Ok(map.into_iter().collect())
}
