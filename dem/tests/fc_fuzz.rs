//! The frictional-contact problem reader never panics: random truncations and byte mutations of
//! a valid problem, and random JSON values, give a typed error or a valid problem (proptest).

use dem::fc::reader::parse_problem;
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
