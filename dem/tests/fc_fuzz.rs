//! The frictional-contact problem reader never panics: random truncations and byte mutations of
//! a valid problem, random sizes that disagree (nc, μ, q, shape of W, indices), negative μ,
//! non-finite literals, ragged dense matrices and cut gzip files give a typed error on one line,
//! or a problem the solver takes without panicking (proptest; `PROPTEST_CASES` sets the number
//! of cases). Inputs that once broke these rules are replayed from `tests/corpus/`.

use dem::fc::reader::{parse_problem, read_problem};
use dem::fc::{solve, FcError, FcOptions};
use proptest::prelude::*;

const VALID: &str = r#"{"format": "fc-problem-v1", "dimension": 2, "nc": 2, "mu": [0.3, 0.5],
 "q": [-1.0, 0.0, -0.5, 0.1],
 "W": {"storage": "coo", "shape": [4, 4], "row": [0, 1, 2, 3, 0, 2], "col": [0, 1, 2, 3, 2, 0],
       "val": [1.0, 3.0, 1.0, 3.0, 0.2, 0.2]}}"#;

#[test]
fn the_valid_problem_reads() {
    let p = parse_problem(VALID.as_bytes()).unwrap();
    assert_eq!(p.contacts(), 2);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, .. ProptestConfig::default() })]

    #[test]
    fn truncated_input_is_an_error(cut in 0usize..VALID.len()) {
        prop_assert!(parse_problem(&VALID.as_bytes()[..cut]).is_err());
    }

    #[test]
    fn mutated_bytes_never_panic(pos in 0usize..VALID.len(), byte in any::<u8>()) {
        let mut b = VALID.as_bytes().to_vec();
        b[pos] = byte;
        let _ = parse_problem(&b);
    }

    #[test]
    fn mutated_numbers_never_panic(idx in 0usize..40, value in prop_oneof![
        Just("-1".to_string()), Just("1e308".to_string()), Just("-0".to_string()),
        Just("999999999999".to_string()), Just("\"x\"".to_string()), Just("null".to_string()),
        Just("[]".to_string()), Just("1.5".to_string()), any::<i32>().prop_map(|i| i.to_string())]) {
        // Replace the idx-th number of the document.
        let mut out = String::new();
        let mut count = 0;
        let mut chars = VALID.chars().peekable();
        while let Some(c) = chars.next() {
            if c.is_ascii_digit() || (c == '-' && chars.peek().is_some_and(|d| d.is_ascii_digit())) {
                let mut num = c.to_string();
                while let Some(&d) = chars.peek() {
                    if d.is_ascii_digit() || d == '.' || d == 'e' || d == '-' { num.push(d); chars.next(); } else { break; }
                }
                out.push_str(if count == idx { &value } else { &num });
                count += 1;
            } else {
                out.push(c);
            }
        }
        let _ = parse_problem(out.as_bytes());
    }
}

/// Longest accepted error message (characters).
const MAX_MESSAGE: usize = 600;

fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// A read either fails with one non-empty line of at most [`MAX_MESSAGE`] characters, or gives a
/// problem that the solver takes without panicking, returning finite `r`, `u` or a typed error.
fn check(bytes: &[u8]) -> Result<Option<FcError>, TestCaseError> {
    match parse_problem(bytes) {
        Err(e) => {
            let m = e.to_string();
            prop_assert!(!m.trim().is_empty(), "empty message");
            prop_assert!(!m.contains('\n') && !m.contains('\r'), "not one line: {m}");
            prop_assert!(m.chars().count() <= MAX_MESSAGE, "too long: {m}");
            Ok(Some(e))
        }
        Ok(p) => {
            let options = FcOptions {
                max_iterations: 50,
                ..Default::default()
            };
            if let Ok(s) = solve(&p, &options) {
                prop_assert!(
                    s.r.iter().chain(&s.u).all(|x| x.is_finite()),
                    "non-finite solution of\n{}",
                    String::from_utf8_lossy(bytes)
                );
            }
            Ok(None)
        }
    }
}

/// A problem in the `coo` layout from its parts, as JSON text.
fn coo(
    nc: &str,
    mu: &[String],
    q: &[String],
    shape: (usize, usize),
    w: &[(usize, usize, String)],
) -> String {
    let list = |v: &[String]| v.join(", ");
    let row: Vec<String> = w.iter().map(|t| t.0.to_string()).collect();
    let col: Vec<String> = w.iter().map(|t| t.1.to_string()).collect();
    let val: Vec<String> = w.iter().map(|t| t.2.clone()).collect();
    format!(
        r#"{{"format": "fc-problem-v1", "dimension": 2, "nc": {nc}, "mu": [{}], "q": [{}],
 "W": {{"storage": "coo", "shape": [{}, {}], "row": [{}], "col": [{}], "val": [{}]}}}}"#,
        list(mu),
        list(q),
        shape.0,
        shape.1,
        list(&row),
        list(&col),
        list(&val)
    )
}

/// Numbers as JSON tokens: ordinary, extreme, negative, and the non-JSON literals some writers
/// emit.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-2.0f64..2.0).prop_map(|x| format!("{x}")),
        1 => prop::sample::select(vec![
            "0", "-0", "1e308", "-1e308", "1e-308", "5e-324", "1e309", "NaN", "Infinity",
            "-Infinity", "nan", "1e400", "-1", "3",
        ]).prop_map(String::from),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(1000)))]

    /// Random sizes: `nc`, the lengths of `mu` and `q`, the shape of W and its triplets (indices
    /// possibly out of range) disagree at random; values include negative μ, NaN and ±∞.
    #[test]
    fn random_sizes_and_values_give_a_typed_error_or_a_solvable_problem(
        nc in prop_oneof![0usize..5, Just(usize::MAX / 2 + 1)],
        mu in prop::collection::vec(number(), 0..6),
        q in prop::collection::vec(number(), 0..12),
        shape in (0usize..12, 0usize..12),
        w in prop::collection::vec((0usize..12, 0usize..12, number()), 0..20),
    ) {
        let text = coo(&nc.to_string(), &mu, &q, shape, &w);
        check(text.as_bytes())?;
    }

    /// Consistent sizes with random (often extreme) values in a dense W: the values decide.
    #[test]
    fn random_values_of_consistent_sizes(
        (nc, mu, q, w) in (1usize..4).prop_flat_map(|nc| (
            Just(nc),
            prop::collection::vec(number(), nc),
            prop::collection::vec(number(), 2 * nc),
            prop::collection::vec(prop::collection::vec(number(), 2 * nc), 2 * nc),
        )),
    ) {
        let rows: Vec<String> = w.iter().map(|r| format!("[{}]", r.join(", "))).collect();
        let text = format!(
            r#"{{"format": "fc-problem-v1", "dimension": 2, "nc": {nc}, "mu": [{}], "q": [{}],
 "W": {{"storage": "dense", "data": [{}]}}}}"#,
            mu.join(", "), q.join(", "), rows.join(", ")
        );
        check(text.as_bytes())?;
    }

    /// A valid problem with one μ made negative is refused naming that contact.
    #[test]
    fn a_negative_friction_is_named(which in 0usize..2, value in -10.0f64..-1e-12) {
        let mut mu = ["0.3".to_string(), "0.5".to_string()];
        mu[which] = format!("{value}");
        let text = VALID.replacen("[0.3, 0.5]", &format!("[{}, {}]", mu[0], mu[1]), 1);
        let e = check(text.as_bytes())?;
        let e = e.map(|e| e.to_string()).unwrap_or_default();
        prop_assert!(e.contains(&format!("mu[{which}]")), "{e}");
    }

    /// Dense W with rows of random lengths: non-square or wrongly sized W is refused.
    #[test]
    fn ragged_dense_matrices_are_refused(rows in prop::collection::vec(prop::collection::vec(number(), 0..6), 0..6)) {
        let data: Vec<String> = rows.iter().map(|r| format!("[{}]", r.join(", "))).collect();
        let text = format!(
            r#"{{"format": "fc-problem-v1", "dimension": 2, "nc": 2, "mu": [0.3, 0.5], "q": [-1, 0, -0.5, 0.1],
 "W": {{"storage": "dense", "data": [{}]}}}}"#,
            data.join(", ")
        );
        let square = rows.len() == 4 && rows.iter().all(|r| r.len() == 4);
        let e = check(text.as_bytes())?;
        if !square {
            prop_assert!(e.is_some(), "accepted a {}-row ragged W", rows.len());
        }
    }

    /// The valid problem cut anywhere and gzip-compressed, read from a file: a typed error.
    #[test]
    fn truncated_gzip_files_are_an_error(cut in 0usize..100) {
        use std::io::Write as _;
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(VALID.as_bytes()).unwrap();
        let gz = gz.finish().unwrap();
        let cut = cut * gz.len() / 100;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.json.gz");
        std::fs::write(&path, &gz[..cut]).unwrap();
        let e = read_problem(&path);
        prop_assert!(e.is_err(), "a gzip file cut at {cut} of {} bytes was read", gz.len());
        let m = e.unwrap_err().to_string();
        prop_assert!(!m.contains('\n') && !m.is_empty(), "{m}");
        prop_assert!(m.contains("p.json.gz"), "the message does not name the file: {m}");
    }
}

/// Every file of `tests/corpus/` (inputs that once broke a rule of this file) is refused with
/// one line naming the file and containing the text given for it in `tests/corpus/EXPECT`
/// (`FILE<TAB>TEXT`).
#[test]
fn corpus_inputs_are_refused_with_their_message() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let manifest = std::fs::read_to_string(dir.join("EXPECT")).unwrap();
    let mut n = 0;
    for line in manifest
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
    {
        let (file, expect) = line
            .split_once('\t')
            .unwrap_or_else(|| panic!("bad line {line:?}"));
        let e = match read_problem(dir.join(file)) {
            Ok(_) => panic!("{file}: read, expected an error containing `{expect}`"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(expect), "{file}: `{expect}` not in `{e}`");
        assert!(
            e.contains(file),
            "{file}: the message does not name the file: `{e}`"
        );
        assert!(!e.contains('\n') && e.len() <= MAX_MESSAGE, "{file}: {e}");
        n += 1;
    }
    let files = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(n + 1, files, "every corpus file has a line in EXPECT");
}
