//! Fuzzing the scenario loader (proptest): the built-in TOMLs with random lines deleted,
//! duplicated, swapped or inserted, values replaced by random tokens (NaN, ±inf, huge and tiny
//! numbers, wrong types), keys misspelt, and random `--set` overrides.
//!
//! Asserted for every input: no panic; an error is one non-empty line of at most
//! [`MAX_MESSAGE`] characters; an input that loads builds its worlds without error (everything
//! the generators and the engine would refuse is refused by the loader first, naming the key).
//!
//! The number of cases is `PROPTEST_CASES` (default [`DEFAULT_CASES`], a few seconds). Inputs that
//! once broke one of these rules live in `tests/corpus/` and are replayed by
//! `corpus_inputs_are_refused_with_their_message`.

mod common;

use std::path::Path;

use grainlaw::scenarios::registry::{from_text, SCENARIOS};
use proptest::prelude::*;
use toml::Table;

/// Longest accepted error message (characters).
const MAX_MESSAGE: usize = 600;

/// Cases per property when `PROPTEST_CASES` is not set.
const DEFAULT_CASES: u32 = 2000;

/// Worlds are built only up to this many grains (time of the suite).
const BUILD_GRAINS: usize = 3_000;

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(DEFAULT_CASES)
}

/// Values that stress the loader: non-finite and extreme floats, out-of-range integers, wrong
/// types, malformed TOML.
const TOKENS: &[&str] = &[
    "nan",
    "+nan",
    "-nan",
    "inf",
    "+inf",
    "-inf",
    "0",
    "-0",
    "0.0",
    "-0.0",
    "-1",
    "-1.5",
    "1",
    "2",
    "3",
    "4",
    "10",
    "100",
    "1000000",
    "1e6",
    "1000000000",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "0.5",
    "0.999",
    "89.999",
    "90",
    "90.0",
    "180",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e-308",
    "5e-324",
    "1e300",
    "1e-300",
    "1e-12",
    "1e-7",
    "1e-3",
    "2.5e-3",
    "1e9",
    "true",
    "false",
    "\"x\"",
    "\"\"",
    "\"1.0\"",
    "[]",
    "[1, 2, 3]",
    "[0.01, 0.02, 0.05]",
    "[nan, 1, 2]",
    "[\"a\"]",
    "{}",
    "{ a = 1 }",
    "{ tolerance = 1e-4, max_iterations = 0 }",
    "{ grain_grain = -0.1, grain_wall = 0.5 }",
    "1979-05-27",
    "07:32:00",
    "=",
    "[",
    "\"unterminated",
    "0x10",
    "1_000",
    "1__0",
    ".5",
    "5.",
];

/// Dotted paths of every leaf value of scenario `which`'s built-in configuration (inline
/// tables included).
fn builtin_leaf_keys(which: usize) -> Vec<String> {
    let t: Table = SCENARIOS[which].builtin_toml().parse().unwrap();
    common::toml_leaves(&t)
        .into_iter()
        .map(|(key, _)| key)
        .collect()
}

/// One mutation of a TOML text, given as line operations.
#[derive(Debug, Clone)]
enum Edit {
    Delete(usize),
    Duplicate(usize),
    Swap(usize, usize),
    Replace(usize, usize),
    Misspell(usize),
    Insert(usize, usize, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        any::<usize>().prop_map(Edit::Delete),
        any::<usize>().prop_map(Edit::Duplicate),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Swap(a, b)),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Replace(a, b)),
        any::<usize>().prop_map(Edit::Misspell),
        (any::<usize>(), any::<usize>(), any::<usize>())
            .prop_map(|(a, b, c)| Edit::Insert(a, b, c)),
    ]
}

fn apply(text: &str, edits: &[Edit], keys: &[String]) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for e in edits {
        let n = lines.len().max(1);
        match *e {
            Edit::Delete(i) => {
                if !lines.is_empty() {
                    lines.remove(i % n);
                }
            }
            Edit::Duplicate(i) => {
                if !lines.is_empty() {
                    let l = lines[i % n].clone();
                    lines.insert(i % n, l);
                }
            }
            Edit::Swap(a, b) => {
                if !lines.is_empty() {
                    lines.swap(a % n, b % n);
                }
            }
            Edit::Replace(i, t) => {
                if let Some(l) = lines.get_mut(i % n) {
                    if let Some((key, _)) = l.split_once('=') {
                        *l = format!("{key}= {}", TOKENS[t % TOKENS.len()]);
                    }
                }
            }
            Edit::Misspell(i) => {
                if let Some(l) = lines.get_mut(i % n) {
                    if let Some((key, rest)) = l.split_once('=') {
                        *l = format!("{}x ={rest}", key.trim_end());
                    }
                }
            }
            Edit::Insert(i, k, t) => {
                // A leaf key's last part at a random line (maybe in the wrong table).
                let key = keys[k % keys.len()].rsplit('.').next().unwrap_or("x");
                lines.insert(
                    i % (lines.len() + 1),
                    format!("{key} = {}", TOKENS[t % TOKENS.len()]),
                );
            }
        }
    }
    lines.join("\n")
}

/// The rules every input must follow (module documentation).
fn check(text: &str, sets: &[String]) -> Result<(), TestCaseError> {
    match from_text("fuzz", "fuzz.toml", text, sets) {
        Err(e) => {
            let m = e.to_string();
            prop_assert!(!m.trim().is_empty(), "empty message");
            prop_assert!(!m.contains('\n') && !m.contains('\r'), "not one line: {m}");
            prop_assert!(m.chars().count() <= MAX_MESSAGE, "message too long: {m}");
        }
        Ok(l) => {
            if l.config.grains() <= BUILD_GRAINS {
                if let Err(e) = l.config.build_first() {
                    prop_assert!(
                        false,
                        "loaded but does not build: {e}\n--set {sets:?}\n{text}"
                    );
                }
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// Built-in scenarios with 1–4 random line edits.
    #[test]
    fn mutated_builtins_load_or_fail_in_one_line(
        which in 0usize..SCENARIOS.len(),
        edits in prop::collection::vec(edit(), 1..5),
    ) {
        let keys = builtin_leaf_keys(which);
        let text = apply(SCENARIOS[which].builtin_toml(), &edits, &keys);
        check(&text, &[])?;
    }

    /// Built-in scenarios with 1–3 random `--set KEY=VALUE`, the key a real leaf key (most of the
    /// time) or a random word, the value a random token.
    #[test]
    fn random_overrides_load_or_fail_in_one_line(
        which in 0usize..SCENARIOS.len(),
        sets in prop::collection::vec(
            (any::<usize>(), any::<usize>(), prop::bool::weighted(0.9), "[a-z_.]{0,12}"), 1..4),
    ) {
        let keys = builtin_leaf_keys(which);
        let sets: Vec<String> = sets
            .into_iter()
            .map(|(k, t, real, word)| {
                let key = if real { keys[k % keys.len()].clone() } else { word };
                format!("{key}={}", TOKENS[t % TOKENS.len()])
            })
            .collect();
        check(SCENARIOS[which].builtin_toml(), &sets)?;
    }

    /// One leaf key of a built-in set to a random finite float over 600 orders of magnitude
    /// (either sign): loads and builds, or fails in one line.
    #[test]
    fn random_magnitudes_load_or_fail_in_one_line(
        which in 0usize..SCENARIOS.len(),
        k in any::<usize>(),
        mantissa in -10.0f64..10.0,
        exponent in -300i32..300,
    ) {
        let keys = builtin_leaf_keys(which);
        let v = mantissa * 10f64.powi(exponent);
        let set = format!("{}={v:e}", keys[k % keys.len()]);
        check(SCENARIOS[which].builtin_toml(), &[set])?;
    }
}

/// Header lines of a corpus file: `# expect: TEXT` (required, the message must contain it) and
/// `# set: KEY=VALUE` (any number).
fn corpus_header(text: &str) -> (Option<String>, Vec<String>) {
    let mut expect = None;
    let mut sets = Vec::new();
    for l in text.lines() {
        if let Some(e) = l.strip_prefix("# expect:") {
            expect = Some(e.trim().to_string());
        } else if let Some(s) = l.strip_prefix("# set:") {
            sets.push(s.trim().to_string());
        }
    }
    (expect, sets)
}

/// Every input of `tests/corpus/` (each once panicked, hung, aborted, or failed with a message
/// that did not name the key) is now refused before any work, with one line containing its
/// `# expect:` text.
#[test]
fn corpus_inputs_are_refused_with_their_message() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let mut n = 0;
    let mut entries: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    entries.sort();
    for path in entries {
        let text = std::fs::read_to_string(&path).unwrap();
        let (expect, sets) = corpus_header(&text);
        let expect = expect.unwrap_or_else(|| panic!("{}: no `# expect:` line", path.display()));
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let e = match from_text("corpus", &name, &text, &sets) {
            Ok(l) => panic!(
                "{name}: loaded ({}), expected an error containing `{expect}`",
                l.config.kind()
            ),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(&expect), "{name}: `{expect}` not in `{e}`");
        assert!(!e.contains('\n') && e.len() <= MAX_MESSAGE, "{name}: {e}");
        n += 1;
    }
    assert!(n >= 10, "only {n} corpus files in {}", dir.display());
}
