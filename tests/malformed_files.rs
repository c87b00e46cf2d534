//! Every parser meets truncated files, wrong types, unknown keywords and absurd numbers with
//! an error — never a panic. Each committed model fixture (TOML, JSON, Abaqus) and an exported
//! Abaqus cell are cut at many points and have numbers replaced by absurd ones; parsing and
//! validating each variant must return (Ok or a typed error) without panicking. The same
//! inputs seed the cargo-fuzz corpora under `fuzz/corpus/`.

use fibercell::io::{parse_abaqus, parse_json, parse_toml, InputError};
use fibercell::model::ModelDescription;
use fibercell::Model;

type Parser = fn(&str, &str) -> Result<ModelDescription, InputError>;

fn parser(path: &str) -> Parser {
    match path.rsplit('.').next() {
        Some("toml") => parse_toml,
        Some("json") => parse_json,
        _ => parse_abaqus,
    }
}

/// Parses and, if that succeeds, validates: both must return, never panic. Returns whether
/// the text was accepted; an accepted model must hold only finite numbers (a loader that let
/// a NaN, an infinity or an overflowing 1e400 through fails here).
fn exercise(parse: Parser, text: &str, name: &str) -> bool {
    let Ok(d) = parse(text, "variant") else {
        return false;
    };
    if Model::from_description(&d).is_err() {
        return false;
    }
    let value = toml::Value::try_from(&d).expect("an accepted description serializes");
    if let Some(bad) = first_non_finite(&value) {
        panic!("{name}: a variant with the non-finite number {bad} was accepted:\n{text}");
    }
    true
}

/// The first float in `v` that is not finite.
fn first_non_finite(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => (!x.is_finite()).then_some(*x),
        toml::Value::Array(items) => items.iter().find_map(first_non_finite),
        toml::Value::Table(t) => t.values().find_map(first_non_finite),
        _ => None,
    }
}

fn inputs() -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = std::fs::read_dir("fixtures")
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            let ext = p.extension()?.to_str()?.to_string();
            matches!(ext.as_str(), "toml" | "json" | "inp")
                .then(|| (p.display().to_string(), std::fs::read_to_string(&p).ok()))
                .and_then(|(n, t)| Some((n, t?)))
        })
        .filter(|(n, _)| !n.contains("params"))
        .collect();
    let knit = fibercell::generate::knitted(&fibercell::generate::Knit::default()).unwrap();
    out.push(("knit.inp".into(), fibercell::io::to_abaqus(&knit).unwrap()));
    out
}

#[test]
fn truncated_files_are_errors_not_panics() {
    for (name, text) in inputs() {
        let parse = parser(&name);
        // Every fixture loads but the bad_ ones, which must not — except the floating fiber,
        // a valid file whose solve fails (tests/bad_input.rs).
        let refused = name.contains("bad_") && !name.ends_with("bad_floating_fiber.toml");
        assert_eq!(
            exercise(parse, &text, &name),
            !refused,
            "{name}: loads exactly when it is not a bad_ fixture"
        );
        let cuts: Vec<usize> = (0..text.len())
            .step_by((text.len() / 200).max(1))
            .filter(|&k| text.is_char_boundary(k))
            .collect();
        for k in cuts {
            exercise(parse, &text[..k], &name);
        }
    }
}

#[test]
fn absurd_numbers_and_wrong_types_are_errors_not_panics() {
    let replacements = [
        "1e400",
        "-1e400",
        "NaN",
        "nan",
        "inf",
        "-0",
        "18446744073709551616",
        "-3",
        "\"text\"",
        "[]",
        "{}",
        "1e-320",
        "99999999999",
    ];
    for (name, text) in inputs() {
        let parse = parser(&name);
        // Every number-like token, one at a time (at most 60 per file), replaced.
        let starts: Vec<usize> = text
            .char_indices()
            .filter(|&(k, c)| {
                (c.is_ascii_digit() || c == '-')
                    && (k == 0 || !text.as_bytes()[k - 1].is_ascii_alphanumeric())
            })
            .map(|(k, _)| k)
            .collect();
        for &start in starts.iter().step_by((starts.len() / 60).max(1)) {
            let end = text[start..]
                .find(|c: char| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '+')))
                .map_or(text.len(), |e| start + e);
            for r in replacements {
                let variant = format!("{}{}{}", &text[..start], r, &text[end..]);
                exercise(parse, &variant, &name);
            }
        }
    }
}

#[test]
fn unknown_keywords_and_keys_name_what_is_unknown() {
    let inp = "*NODE\n1, 0, 0, 0\n*DENSITY\n7800\n";
    match parse_abaqus(inp, "m.inp") {
        Err(InputError::UnsupportedKeyword {
            line: 3, keyword, ..
        }) => {
            assert_eq!(keyword, "DENSITY")
        }
        other => panic!("{other:?}"),
    }
    // (parser, text, word the message names, line)
    for (parse, text, key, at) in [
        (
            parse_toml as Parser,
            "[[nodes]]\nid = 1\nx = [0, 0, 0]\nmass = 2\n",
            "mass",
            4,
        ),
        (parse_json as Parser, "{\"nodez\": []}", "nodez", 1),
        (
            parse_toml as Parser,
            "[cell]\nsize = [1.0]\n",
            "an array of 2 numbers",
            2,
        ),
        (
            parse_toml as Parser,
            "[[fibers]]\nid = 1\nnodes = [1, 2]\nradius = \"thin\"\n",
            "string",
            4,
        ),
    ] {
        match parse(text, "m") {
            Err(InputError::Syntax { message, line, .. }) => {
                assert!(message.contains(key), "{message}");
                assert_eq!(line, at, "{message}");
            }
            other => panic!("{other:?}"),
        }
    }
}
