//! Mutations of RON text: characters, tokens, numbers, ids, identifiers,
//! entries of bracketed groups, truncation.

use super::Rng;
use std::ops::Range;

/// What a token is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A quoted string.
    Str,
    /// A number (`inf` and `NaN` included).
    Num,
    /// An identifier (field, variant, `Some`, `true`).
    Ident,
    /// One punctuation character.
    Punct,
    /// Spaces and line breaks.
    Space,
    /// A `//` or `/* */` comment.
    Comment,
}

/// A token: its kind and byte range.
#[derive(Clone, Debug)]
pub struct Token {
    /// Kind.
    pub kind: Kind,
    /// Byte range in the text.
    pub span: Range<usize>,
}

/// Splits RON text into tokens (never fails: anything else is punctuation).
pub fn tokenize(s: &str) -> Vec<Token> {
    let b = s.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        let start = i;
        let c = b[i];
        let kind = if c.is_ascii_whitespace() {
            while i < b.len() && b[i].is_ascii_whitespace() {
                i += 1;
            }
            Kind::Space
        } else if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            Kind::Comment
        } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                i += 1;
            }
            i = (i + 2).min(b.len());
            Kind::Comment
        } else if c == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i = (i + 1).min(b.len());
            Kind::Str
        } else if c.is_ascii_digit()
            || ((c == b'-' || c == b'+' || c == b'.')
                && b.get(i + 1)
                    .is_some_and(|d| d.is_ascii_digit() || *d == b'.'))
        {
            i += 1;
            while i < b.len() {
                let d = b[i];
                let sign_of_exponent = (d == b'-' || d == b'+') && matches!(b[i - 1], b'e' | b'E');
                if d.is_ascii_alphanumeric() || d == b'.' || d == b'_' || sign_of_exponent {
                    i += 1;
                } else {
                    break;
                }
            }
            Kind::Num
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            if matches!(&s[start..i], "inf" | "NaN") {
                Kind::Num
            } else {
                Kind::Ident
            }
        } else {
            // one character (UTF-8 aware)
            i += s[i..].chars().next().map_or(1, char::len_utf8);
            Kind::Punct
        };
        out.push(Token {
            kind,
            span: start..i,
        });
    }
    out
}

/// Numbers that break things: non-finite, zero, negative, huge, tiny,
/// integers at the limits of their types.
pub const SPECIAL_NUMBERS: &[&str] = &[
    "NaN",
    "inf",
    "-inf",
    "0",
    "0.0",
    "-0.0",
    "-1",
    "-1.0",
    "1",
    "1.0",
    "2",
    "3",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e-308",
    "5e-324",
    "1e-12",
    "1e12",
    "1e20",
    "255",
    "256",
    "65536",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "9223372036854775807",
    "-9223372036854775808",
    "1000001",
    "0.5",
    "-0.5",
    "3.141592653589793",
];

/// Identifiers of the scene format and RON, for replacing one by another.
pub const VOCABULARY: &[&str] = &[
    "Planar",
    "Spatial",
    "Beam",
    "Truss",
    "Hinge",
    "PointMass",
    "RigidBody",
    "Superelement",
    "Node",
    "Coord",
    "Def",
    "Modes",
    "X",
    "Y",
    "Z",
    "Angle",
    "Lambda",
    "Position",
    "Orientation",
    "Rotation",
    "Deformation",
    "Stress",
    "Energies",
    "Dofs",
    "Deformations",
    "NodalCoordinates",
    "Explicit",
    "Constant",
    "Ramp",
    "RaisedCosinePulse",
    "SpinUp",
    "Sine",
    "SkewSineMoves",
    "PiecewisePolynomial",
    "Hermite",
    "Table",
    "Scaled",
    "Sum",
    "Rectangle",
    "Circle",
    "Tube",
    "User",
    "Some",
    "None",
    "true",
    "false",
    "B1",
    "B2",
    "B3",
    "n",
    "at",
    "id",
    "nodes",
    "elements",
    "fixed",
    "rigid",
    "prescribed",
    "dofs",
    "dofs_first",
    "loads",
    "gravity",
    "position_of",
    "up",
    "axis",
    "mass",
    "inertia",
    "com",
    "e",
    "g",
    "nu",
    "rho",
];

/// Characters to insert.
const CHARS: &[char] = &[
    '(', ')', '[', ']', '{', '}', ',', ':', '"', '0', '9', '.', '-', 'e', 'a', ' ', '\n', '/',
    '\\', 'é', '\u{0}',
];

fn char_boundaries(s: &str) -> Vec<usize> {
    s.char_indices().map(|(i, _)| i).collect()
}

fn of_kind(tokens: &[Token], k: Kind) -> Vec<usize> {
    (0..tokens.len()).filter(|&i| tokens[i].kind == k).collect()
}

fn replace(s: &mut String, r: Range<usize>, with: &str) {
    s.replace_range(r, with);
}

/// The bracketed groups of a text: (open, close) token indices of matching
/// brackets.
fn groups(text: &str, tokens: &[Token]) -> Vec<(usize, usize)> {
    let mut stack: Vec<(usize, u8)> = vec![];
    let mut out = vec![];
    for (i, t) in tokens.iter().enumerate() {
        if t.kind != Kind::Punct {
            continue;
        }
        let c = text.as_bytes()[t.span.start];
        match c {
            b'(' | b'[' | b'{' => stack.push((i, c)),
            b')' | b']' | b'}' => {
                let open = match c {
                    b')' => b'(',
                    b']' => b'[',
                    _ => b'{',
                };
                if let Some(&(j, o)) = stack.last() {
                    if o == open {
                        stack.pop();
                        out.push((j, i));
                    }
                }
            }
            _ => {}
        }
    }
    out
}

/// The comma-separated items of a group, as byte ranges of the text (each
/// trimmed of surrounding whitespace), and the group's bracket.
fn items(text: &str, tokens: &[Token], (open, close): (usize, usize)) -> Vec<Range<usize>> {
    let mut out = vec![];
    let mut depth = 0i32;
    let mut start = tokens[open].span.end;
    for t in &tokens[open + 1..close] {
        if t.kind == Kind::Punct {
            match text.as_bytes()[t.span.start] {
                b'(' | b'[' | b'{' => depth += 1,
                b')' | b']' | b'}' => depth -= 1,
                b',' if depth == 0 => {
                    out.push(start..t.span.start);
                    start = t.span.end;
                }
                _ => {}
            }
        }
    }
    out.push(start..tokens[close].span.start);
    out.into_iter()
        .map(|r| {
            let s = &text[r.clone()];
            let lead = s.len() - s.trim_start().len();
            let trail = s.len() - s.trim_end().len();
            r.start + lead..r.end - trail
        })
        .filter(|r| !r.is_empty())
        .collect()
}

/// A number near `v` or an unusual one, as RON text.
fn number(rng: &mut Rng, old: &str) -> String {
    if rng.chance(0.6) {
        return rng.pick(SPECIAL_NUMBERS).to_string();
    }
    let v: f64 = old.parse().unwrap_or(1.0);
    let w = match rng.below(5) {
        0 => -v,
        1 => v * 10f64.powi(rng.below(13) as i32 - 6),
        2 => v * (1.0 + 1e-9 * (rng.unit() - 0.5)),
        3 => v + 1.0,
        _ => (rng.unit() - 0.5) * 10f64.powi(rng.below(7) as i32 - 3),
    };
    if old.contains(['.', 'e', 'E']) || !w.is_finite() || w.fract() != 0.0 {
        format!("{w:?}")
    } else {
        format!("{}", w as i64)
    }
}

/// Applies one text mutation; `other` is another scene of the corpus (for
/// splicing). Returns a description.
pub fn mutate(text: &mut String, other: &str, rng: &mut Rng) -> String {
    let tokens = tokenize(text);
    let nonspace: Vec<usize> = (0..tokens.len())
        .filter(|&i| !matches!(tokens[i].kind, Kind::Space | Kind::Comment))
        .collect();
    if nonspace.is_empty() {
        text.push_str("()");
        return "appended ()".into();
    }
    for _ in 0..8 {
        let op = rng.below(16);
        match op {
            // characters
            0..=2 => {
                let bs = char_boundaries(text);
                let at = bs[rng.below(bs.len())];
                let len = text[at..].chars().next().map_or(0, char::len_utf8);
                let what = match op {
                    0 => {
                        text.replace_range(at..at + len, "");
                        "deleted a character"
                    }
                    1 => {
                        let c = rng.pick(CHARS).to_string();
                        text.insert_str(at, &c);
                        "inserted a character"
                    }
                    _ => {
                        let c = text[at..at + len].to_string();
                        text.insert_str(at, &c);
                        "duplicated a character"
                    }
                };
                return format!("{what} at byte {at}");
            }
            // tokens
            3 => {
                let t = &tokens[*rng.pick(&nonspace)];
                let r = t.span.clone();
                replace(text, r.clone(), "");
                return format!("deleted token at byte {}", r.start);
            }
            4 => {
                let t = &tokens[*rng.pick(&nonspace)];
                let s = text[t.span.clone()].to_string();
                text.insert_str(t.span.start, &s);
                return format!("duplicated token {s:?}");
            }
            5 => {
                let a = *rng.pick(&nonspace);
                let b = *rng.pick(&nonspace);
                let (a, b) = (a.min(b), a.max(b));
                if a == b {
                    continue;
                }
                let (ra, rb) = (tokens[a].span.clone(), tokens[b].span.clone());
                let (sa, sb) = (text[ra.clone()].to_string(), text[rb.clone()].to_string());
                replace(text, rb, &sa);
                replace(text, ra, &sb);
                return format!("swapped tokens {sa:?} and {sb:?}");
            }
            // numbers
            6 | 7 => {
                let nums = of_kind(&tokens, Kind::Num);
                if nums.is_empty() {
                    continue;
                }
                let t = &tokens[*rng.pick(&nums)];
                let old = text[t.span.clone()].to_string();
                let new = number(rng, &old);
                replace(text, t.span.clone(), &new);
                return format!("number {old} -> {new}");
            }
            // strings (ids)
            8 | 9 => {
                let strs = of_kind(&tokens, Kind::Str);
                if strs.is_empty() {
                    continue;
                }
                let t = &tokens[*rng.pick(&strs)];
                let old = text[t.span.clone()].to_string();
                let inner = old.trim_matches('"').to_string();
                let new = match rng.below(7) {
                    0 => text[tokens[*rng.pick(&strs)].span.clone()].to_string(),
                    1 => "\"\"".to_string(),
                    2 => format!("\"{inner}.n1\""),
                    3 => format!("\"{inner}.1\""),
                    4 => format!("\"{inner}x\""),
                    5 => format!("\"{}\"", inner.chars().skip(1).collect::<String>()),
                    _ => format!("\"{}\"", "é*".repeat(1 + rng.below(40))),
                };
                replace(text, t.span.clone(), &new);
                return format!("string {old} -> {new}");
            }
            // identifiers
            10 => {
                let ids = of_kind(&tokens, Kind::Ident);
                if ids.is_empty() {
                    continue;
                }
                let t = &tokens[*rng.pick(&ids)];
                let old = text[t.span.clone()].to_string();
                let new = if rng.chance(0.7) {
                    rng.pick(VOCABULARY).to_string()
                } else {
                    text[tokens[*rng.pick(&ids)].span.clone()].to_string()
                };
                replace(text, t.span.clone(), &new);
                return format!("identifier {old} -> {new}");
            }
            // entries of a group: drop, duplicate, swap, splice
            11..=14 => {
                let gs = groups(text, &tokens);
                if gs.is_empty() {
                    continue;
                }
                let g = *rng.pick(&gs);
                let its = items(text, &tokens, g);
                if its.is_empty() {
                    continue;
                }
                let i = rng.below(its.len());
                let r = its[i].clone();
                let at = tokens[g.0].span.start;
                match op {
                    11 => {
                        // the entry and its comma
                        let mut end = r.end;
                        let rest = &text[end..];
                        if let Some(k) = rest.find(|c: char| !c.is_whitespace()) {
                            if rest[k..].starts_with(',') {
                                end += k + 1;
                            }
                        }
                        let s = text[r.start..end].to_string();
                        replace(text, r.start..end, "");
                        return format!("dropped entry {} of group at byte {at}", short(&s));
                    }
                    12 => {
                        let s = text[r.clone()].to_string();
                        text.insert_str(r.end, &format!(", {s}"));
                        return format!("duplicated entry {} of group at byte {at}", short(&s));
                    }
                    13 => {
                        let j = rng.below(its.len());
                        if i == j {
                            continue;
                        }
                        let (a, b) = (its[i.min(j)].clone(), its[i.max(j)].clone());
                        let (sa, sb) = (text[a.clone()].to_string(), text[b.clone()].to_string());
                        replace(text, b, &sa);
                        replace(text, a, &sb);
                        return format!("swapped entries {i} and {j} of group at byte {at}");
                    }
                    _ => {
                        // an entry of a group of the other scene with the same bracket
                        let ot = tokenize(other);
                        let bracket = text.as_bytes()[tokens[g.0].span.start];
                        let og: Vec<_> = groups(other, &ot)
                            .into_iter()
                            .filter(|h| other.as_bytes()[ot[h.0].span.start] == bracket)
                            .collect();
                        if og.is_empty() {
                            continue;
                        }
                        let h = *rng.pick(&og);
                        let oi = items(other, &ot, h);
                        if oi.is_empty() {
                            continue;
                        }
                        let s = other[rng.pick(&oi).clone()].to_string();
                        replace(text, r, &s);
                        return format!(
                            "entry {i} of group at byte {at} replaced by {}",
                            short(&s)
                        );
                    }
                }
            }
            // truncation
            _ => {
                let bs = char_boundaries(text);
                let at = bs[rng.below(bs.len())];
                text.truncate(at);
                return format!("truncated at byte {at}");
            }
        }
    }
    text.push(')');
    "appended )".into()
}

fn short(s: &str) -> String {
    let one: String = s.split_whitespace().collect::<Vec<_>>().join(" ");
    if one.chars().count() > 60 {
        format!("{:?}…", one.chars().take(60).collect::<String>())
    } else {
        format!("{one:?}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_cover_the_text() {
        let s = r#"( a: [1.0e-3, -2, inf], "x\"y": Some(NaN) ) // c"#;
        let t = tokenize(s);
        let joined: String = t.iter().map(|t| &s[t.span.clone()]).collect();
        assert_eq!(joined, s);
        let nums: Vec<&str> = t
            .iter()
            .filter(|t| t.kind == Kind::Num)
            .map(|t| &s[t.span.clone()])
            .collect();
        assert_eq!(nums, ["1.0e-3", "-2", "inf", "NaN"]);
        let strs = t.iter().filter(|t| t.kind == Kind::Str).count();
        assert_eq!(strs, 1);
    }

    #[test]
    fn items_split_at_top_level_commas() {
        let s = "[ (a: 1, b: 2), (c: [3, 4]) , ]";
        let t = tokenize(s);
        let gs = groups(s, &t);
        let outer = *gs.iter().max_by_key(|g| g.1 - g.0).unwrap();
        let it: Vec<&str> = items(s, &t, outer).into_iter().map(|r| &s[r]).collect();
        assert_eq!(it, ["(a: 1, b: 2)", "(c: [3, 4])"]);
    }
}
