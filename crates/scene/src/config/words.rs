//! Reading errors in a person's words: serde names Rust types (`u32`, `struct MotorConfig`,
//! `a sequence`) and repeats whole values; these say what is allowed, show a value cut short,
//! and suggest the closest key or name.

/// Rust type names as serde writes them after "expected", and what they mean.
const TYPES: &[(&str, &str)] = &[
    ("u8", "a whole number from 0 to 255"),
    ("u16", "a whole number from 0 to 65535"),
    ("u32", "a whole number from 0 to 4294967295"),
    ("u64", "a whole number from 0 to 18446744073709551615"),
    ("usize", "a whole number from 0"),
    ("i32", "a whole number"),
    ("i64", "a whole number"),
    ("f32", "a number"),
    ("f64", "a number"),
    ("a boolean", "true or false"),
    ("a string", "text in quotes"),
    ("a sequence", "a list [...]"),
    ("a map", "a table"),
];

/// A TOML file's reading error in words: where (line and column) and what, without the
/// source lines it quotes, the message put [`in_words`].
pub fn toml_in_words(text: &str, e: &toml::de::Error) -> String {
    let what = in_words(e.message().lines().next().unwrap_or_default().trim());
    match e.span() {
        Some(span) => {
            let before = &text.as_bytes()[..span.start.min(text.len())];
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let column = before.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
            format!("line {line}, column {column}: {what}")
        }
        None => what,
    }
}

/// `message` (a serde or TOML reading error) in words: type names replaced by what they
/// allow, quoted values shortened, and for an unknown key or name the closest one suggested.
pub fn in_words(message: &str) -> String {
    let mut out = shorten_quoted(message.trim());
    if let Some((_, expected)) = out.rsplit_once(", expected ") {
        let expected = expected.to_string();
        let words = if expected.starts_with("struct ") {
            "a table".to_string()
        } else if expected.starts_with("internally tagged enum ") {
            // the sensor's model, the one enum read so
            "a table with a `kind` key (structured-light, time-of-flight, kinect or ideal)"
                .to_string()
        } else if let Some(&(_, words)) = TYPES.iter().find(|(t, _)| *t == expected) {
            words.to_string()
        } else {
            expected.clone()
        };
        out.truncate(out.len() - expected.len());
        out.push_str(&words);
    }
    for (kind, plain) in [
        ("invalid type: ", "got "),
        ("invalid value: ", "got "),
        ("invalid length ", "got length "),
    ] {
        out = out.replacen(kind, plain, 1);
    }
    out = out.replace("sequence", "a list");
    for what in ["unknown field `", "unknown variant `"] {
        if let Some(rest) = message.split_once(what).map(|(_, r)| r)
            && let Some((given, options)) = rest.split_once('`')
        {
            let names: Vec<&str> = options.split('`').skip(1).step_by(2).collect();
            out.push_str(&motorgen::did_you_mean(given, names));
        }
    }
    out
}

/// Quoted parts (`"…"` or `` `…` ``) longer than 40 characters, shortened.
fn shorten_quoted(message: &str) -> String {
    let mut out = String::new();
    let mut rest = message;
    while let Some(start) = rest.find(['"', '`']) {
        let quote = rest[start..].chars().next().expect("a quote");
        let body = &rest[start + 1..];
        let Some(end) = body.find(quote) else {
            break;
        };
        out.push_str(&rest[..=start]);
        out.push_str(&motorgen::shown(&body[..end]));
        out.push(quote);
        rest = &body[end + 1..];
    }
    out.push_str(rest);
    out
}
