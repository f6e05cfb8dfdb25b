//! Names (of plants, campaigns) come from files a user may not have written. Before they reach
//! an output they are made harmless for it:
//! * [`for_terminal`]: control characters (escape sequences, NUL, newlines, DEL, C1 controls)
//!   and bidirectional-text controls become visible `\u{…}` escapes, so they can neither move
//!   the cursor, forge lines nor reorder them;
//! * [`for_csv`]: control characters are escaped the same way, and a field that a spreadsheet
//!   would take for a formula (it starts with `=`, `+`, `-`, `@`, tab or carriage return) gets a
//!   leading `'` (OWASP's advice against CSV injection); quoting is left to the CSV writer;
//! * [`for_latex`]: control characters are dropped and the LaTeX specials are escaped (every
//!   LaTeX table goes through it, also as `latex::escape`);
//! * [`as_key`]: a name as an identifier part (a file name, a LaTeX label) of allowed characters
//!   only, bounded in length, and unique: when the name had to change, a short hash of it is
//!   appended, so two names never share a key (`X+1` and `X_1` once shared figure files).

/// `name` with every character that `keep` refuses replaced by `replacement` (an allowed ASCII
/// character). When that changed the name, or it is longer than `max_len` bytes (≥ 9), the result
/// is cut to `max_len − 9` bytes and `-` plus the first 8 hex digits of the name's SHA-256 is
/// appended.
pub fn as_key(name: &str, keep: impl Fn(char) -> bool, replacement: char, max_len: usize) -> String {
    use sha2::Digest;
    let clean: String = name.chars().map(|c| if c.is_ascii() && keep(c) { c } else { replacement }).collect();
    if clean == name && clean.len() <= max_len {
        return clean;
    }
    let hash: String = sha2::Sha256::digest(name.as_bytes())[..4].iter().map(|b| format!("{b:02x}")).collect();
    // `clean` is ASCII: any byte length is a character boundary.
    format!("{}-{hash}", &clean[..clean.len().min(max_len.saturating_sub(9))])
}

/// Whether `c` must not reach an output raw: a control character, or a bidirectional-text
/// control (U+061C, U+200E/F, U+202A–U+202E, U+2066–U+2069), which reorders what follows it on
/// the line (a name with U+202E displayed the rest of a `run` line reversed: CVE-2021-42574's
/// "Trojan Source").
fn is_control(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{061c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

fn escape_controls(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if is_control(c) {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// `s` for a terminal: control characters as `\u{1b}` style escapes.
pub fn for_terminal(s: &str) -> String {
    escape_controls(s)
}

/// `s` as a CSV field: control characters escaped, formula-like starts defused with `'`.
pub fn for_csv(s: &str) -> String {
    let out = escape_controls(s);
    if s.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        format!("'{out}")
    } else {
        out
    }
}

/// `s` for LaTeX text: escapes LaTeX specials (`\ & % $ # _ { } ~ ^`) and drops control
/// characters (a newline or NUL in a name must not end a table row or break the file).
pub fn for_latex(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            c if c.is_control() => {}
            '\\' => out.push_str("\\textbackslash{}"),
            '&' | '%' | '$' | '#' | '_' | '{' | '}' => {
                out.push('\\');
                out.push(c);
            }
            '~' => out.push_str("\\textasciitilde{}"),
            '^' => out.push_str("\\textasciicircum{}"),
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terminal_sees_no_control_characters() {
        let s = for_terminal("HE1\x1b[2J\0\nx\u{9b}y\u{7f}");
        assert!(!s.chars().any(char::is_control), "{s:?}");
        assert_eq!(s, "HE1\\u{1b}[2J\\u{0}\\u{a}x\\u{9b}y\\u{7f}");
        assert_eq!(for_terminal("AC10 ε"), "AC10 ε");
        assert_eq!(for_terminal("AC\u{202e}01\u{2066}x"), "AC\\u{202e}01\\u{2066}x");
    }

    #[test]
    fn csv_formulas_are_defused() {
        for bad in ["=HYPERLINK(\"http://x\")", "+cmd|' /C calc'!A0", "-2+3", "@SUM(A1)", "\tx", "\rx"] {
            let s = for_csv(bad);
            assert!(s.starts_with('\''), "{bad:?} → {s:?}");
            assert!(!s.chars().any(char::is_control), "{s:?}");
        }
        assert_eq!(for_csv("HE1"), "HE1");
        assert_eq!(for_csv("a=b"), "a=b");
    }

    #[test]
    fn latex_gets_no_controls_or_raw_specials() {
        assert_eq!(for_latex("a_b\n\\input{x}\0"), "a\\_b\\textbackslash{}input\\{x\\}");
    }
}
