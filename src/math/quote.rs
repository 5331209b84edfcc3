//! User values quoted in messages: shortened, with control characters escaped, so that an error about a
//! 4 MiB name (or a name holding terminal escape sequences) stays one readable line.
//!
//! Messages stentkit writes quote values with [`quoted`]; messages that come from elsewhere (serde_yaml's,
//! which quote unknown fields and enum words in backticks and strings in double quotes) pass through
//! [`shortened_message`] before they reach the designer.

use std::borrow::Cow;

/// Characters of a user value shown before it is cut: 40, enough to show any real name whole.
pub const QUOTED_CHARS: usize = 40;

/// Longest field path shown whole \[characters\]: the format's paths have at most about 40
/// (`conditions[12].displacement[2]`); a longer one holds a user's key.
pub const MAX_FIELD_CHARS: usize = 200;

/// Most digits a number keeps in a message: 20, those of the largest `u64`. A longer run is a floating-point
/// number written out in full (Rust's `{}` writes `1e308` with 309 digits, and `{:.3}` adds three more), which
/// [`shortened_numbers`] rewrites in its short form ([`super::Short`]).
pub const MAX_NUMBER_DIGITS: usize = 20;

/// Longest message shown whole \[characters\]; a longer one (after its quoted values are shortened) is cut.
/// stentkit's longest messages (an unknown field with the list of allowed ones) have about 300.
pub const MAX_MESSAGE_CHARS: usize = 1000;

/// `text` with control characters escaped (`\n`, `\u{1b}`), cut after `limit` characters with `…` and the
/// full length in characters: `aaaa… (52428800 characters)`.
fn cut(text: &str, limit: usize) -> Cow<'_, str> {
    let long = text.chars().nth(limit).is_some();
    if !long && !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut out = String::new();
    for c in text.chars().take(limit) {
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    if long {
        out.push('…');
    }
    Cow::Owned(out)
}

/// The length note after a cut value: ` (N characters)`, empty when nothing was cut.
fn length_note(text: &str, limit: usize) -> String {
    if text.chars().nth(limit).is_some() {
        format!(" ({} characters)", text.chars().count())
    } else {
        String::new()
    }
}

/// `value` in backticks for a message: control characters escaped, and cut after [`QUOTED_CHARS`]
/// characters with `…` and its full length, `` `aaaa…` (52428800 characters) ``.
pub fn quoted(value: &str) -> String {
    quoted_up_to(value, QUOTED_CHARS)
}

/// [`quoted`] with `limit` characters shown instead of [`QUOTED_CHARS`] (a file's path is shown whole).
pub fn quoted_up_to(value: &str, limit: usize) -> String {
    format!("`{}`{}", cut(value, limit), length_note(value, limit))
}

/// `text` (a field path, say) shortened like a quoted value but without backticks, when longer than `limit`
/// characters.
pub fn shortened(text: &str, limit: usize) -> Cow<'_, str> {
    match cut(text, limit) {
        Cow::Borrowed(t) => Cow::Borrowed(t),
        Cow::Owned(t) => Cow::Owned(t + &length_note(text, limit)),
    }
}

/// `message` with every number of more than [`MAX_NUMBER_DIGITS`] digits (a floating-point number written out
/// in full) in its short form: `1e308`, not 309 digits. Linear in the message's length.
pub fn shortened_numbers(message: &str) -> Cow<'_, str> {
    let bytes = message.as_bytes();
    let mut out = String::new();
    let (mut copied, mut i) = (0, 0);
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            && (i == 0 || !(bytes[i - 1].is_ascii_digit() || bytes[i - 1] == b'.'));
        if !starts {
            i += 1;
            continue;
        }
        let mut end = i;
        while end < bytes.len() && bytes[end].is_ascii_digit() {
            end += 1;
        }
        let mut digits = end - i;
        if end + 1 < bytes.len() && bytes[end] == b'.' && bytes[end + 1].is_ascii_digit() {
            let fraction = end + 1;
            end = fraction;
            while end < bytes.len() && bytes[end].is_ascii_digit() {
                end += 1;
            }
            digits += end - fraction;
        }
        if digits > MAX_NUMBER_DIGITS
            && let Ok(x) = message[i..end].parse::<f64>()
        {
            out.push_str(&message[copied..i]);
            out.push_str(&super::Short(x).to_string());
            copied = end;
        }
        i = end;
    }
    if copied == 0 {
        Cow::Borrowed(message)
    } else {
        out.push_str(&message[copied..]);
        Cow::Owned(out)
    }
}

/// A message from elsewhere with its long numbers written short ([`shortened_numbers`]) and every value quoted
/// in backticks or double quotes shortened as by [`quoted`], then cut at [`MAX_MESSAGE_CHARS`] if still longer.
/// Linear in the message's length.
pub fn shortened_message(message: &str) -> Cow<'_, str> {
    match shortened_numbers(message) {
        Cow::Borrowed(message) => shortened_quotes(message),
        Cow::Owned(message) => Cow::Owned(shortened_quotes(&message).into_owned()),
    }
}

/// [`shortened_message`] but for the numbers.
fn shortened_quotes(message: &str) -> Cow<'_, str> {
    let mut out = String::new();
    let mut copied = 0;
    let mut rest = message.char_indices();
    while let Some((start, c)) = rest.next() {
        if c != '`' && c != '"' {
            continue;
        }
        // The closing delimiter (a double-quoted value escapes with backslashes).
        let mut escaped = false;
        let mut end = None;
        for (i, d) in rest.by_ref() {
            if escaped {
                escaped = false;
            } else if d == '\\' && c == '"' {
                escaped = true;
            } else if d == c {
                end = Some(i);
                break;
            }
        }
        let stop = end.unwrap_or(message.len());
        let value = &message[start + 1..stop];
        // (A value [`quoted`] already cut has QUOTED_CHARS characters and the `…`: left as it is.)
        if value.chars().nth(QUOTED_CHARS + 1).is_some() {
            out.push_str(&message[copied..=start]);
            out.push_str(&cut(value, QUOTED_CHARS));
            if end.is_some() {
                out.push(c);
            }
            out.push_str(&length_note(value, QUOTED_CHARS));
            copied = end.map_or(message.len(), |e| e + c.len_utf8());
        }
        if end.is_none() {
            break;
        }
    }
    let whole: Cow<'_, str> = if copied == 0 {
        Cow::Borrowed(message)
    } else {
        out.push_str(&message[copied..]);
        Cow::Owned(out)
    };
    if whole.chars().nth(MAX_MESSAGE_CHARS).is_some() {
        Cow::Owned(shortened(&whole, MAX_MESSAGE_CHARS).into_owned())
    } else {
        whole
    }
}

/// A time for messages: at most 9 decimals, trailing zeros dropped (`0.1`, not `0.10000000000000005`).
pub fn short_time(t: super::Real) -> String {
    // Far from the seconds a run spans (1e300 after a typo), fixed-point would print hundreds of digits.
    if !(1e-9..1e9).contains(&t.abs()) && t != 0.0 {
        return super::Short(t).to_string();
    }
    let s = format!("{t:.9}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    // Expected strings written out by hand from the rules above.
    #[test]
    fn long_values_are_cut_with_their_length_and_control_characters_escaped() {
        assert_eq!(quoted("beam"), "`beam`");
        let long = "a".repeat(50_000_000);
        assert_eq!(
            quoted(&long),
            format!("`{}…` (50000000 characters)", "a".repeat(40))
        );
        assert_eq!(quoted("red\u{1b}[31m\n"), "`red\\u{1b}[31m\\n`");
        let exactly = "é".repeat(QUOTED_CHARS);
        assert_eq!(quoted(&exactly), format!("`{exactly}`"));
        assert_eq!(shortened("patches[0].name", 200), "patches[0].name");
    }

    #[test]
    fn numbers_written_out_in_full_are_written_short() {
        // Rust's `{}` of 1e308 is a 1 and 308 zeros; `{:.3}` adds `.000`. Up to 20 digits (a u64) stay.
        let full = format!("{}", 1e308);
        assert_eq!(full.len(), 309);
        assert_eq!(
            shortened_numbers(&format!(
                "Δr = -{full} must be smaller; |angle| = {:.3}°",
                1e308
            )),
            "Δr = -1e308 must be smaller; |angle| = 1e308°"
        );
        let kept = "18446744073709551615 and 3.14159 and 1e308 and 2026-11-26";
        assert_eq!(shortened_numbers(kept), kept);
        assert_eq!(
            shortened_message(&format!(
                "invalid type: floating point `{full}`, expected usize"
            )),
            "invalid type: floating point `1e308`, expected usize"
        );
    }

    #[test]
    fn foreign_messages_get_their_quoted_values_shortened() {
        let word = "x".repeat(100);
        let message = format!("unknown variant `{word}`, expected `SI` or `mm-N-MPa`");
        assert_eq!(
            shortened_message(&message),
            format!(
                "unknown variant `{}…` (100 characters), expected `SI` or `mm-N-MPa`",
                "x".repeat(40)
            )
        );
        let string = format!(
            "invalid type: string \"{}\\\"{}\", expected f64",
            "y".repeat(30),
            "z".repeat(30)
        );
        let short = shortened_message(&string);
        assert!(
            short.starts_with(&format!("invalid type: string \"{}\\\"", "y".repeat(30)))
                && short.ends_with("\" (62 characters), expected f64"),
            "{short}"
        );
        // Short quotes and already quoted values are left alone; an unterminated long one is cut too, and so is
        // a long message.
        assert_eq!(shortened_message("no node `a` here"), "no node `a` here");
        let done = format!("no node {}", quoted(&"n".repeat(99)));
        assert_eq!(shortened_message(&done), done);
        let open = format!("trailing `{}", "w".repeat(90));
        assert_eq!(
            shortened_message(&open),
            format!("trailing `{}… (90 characters)", "w".repeat(40))
        );
        let plain = "v".repeat(5000);
        assert_eq!(
            shortened_message(&plain).chars().count(),
            MAX_MESSAGE_CHARS + 1 + " (5000 characters)".len()
        );
    }
}
