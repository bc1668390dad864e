//! The laws a scenario fits and the data each needs, checked before the run: a plan that cannot
//! identify a law is refused at start (one line naming the key, exit 2), unless the law is
//! explicitly left out (`leave_out = ["mu-i"]`, said at the start of the run), rather than
//! learnt from a refusal at the end of a long run. `grainlaw scenarios --show NAME` prints the
//! same needs ([`describe`]).
//!
//! A fit of `p` parameters needs `p + 2` points (`identify::fit::min_points`): two degrees of
//! freedom of the residuals at least. The needs of each law:
//!
//! | law | scenarios | key | at least | why |
//! |---|---|---|---|---|
//! | `mu-i` | shear-cell, simple-shear | `inertial_numbers` | 5 | 3 parameters + 2 |
//! | `mu-i-linear` (fitted when `mu-i` is left out or refused) | shear-cell, simple-shear | `inertial_numbers` | 4 | 2 parameters + 2 |
//! | `phi-i` | shear-cell, simple-shear | `inertial_numbers` | 4 | 2 parameters + 2 |
//! | `wall-law` | shear-cell | `inertial_numbers` | 3 | 3 parameters + 2, from both walls of each run |
//! | `mohr-coulomb` | biaxial | `confining_pressures` | 3 | the envelope through the origin (1 parameter) + 2; 4 for a free cohesion |
//! | `critical-state` | biaxial | `confining_pressures` | 2 | an interval from the scatter between samples needs two (`identify::critical_state`) |
//! | `stress-dilatancy` | biaxial | — | 4 dilatancy windows before the peaks | known after the run |
//! | `janssen` | janssen | — | 4 depth bins in the fit window | known after the run |

use datasets::error::{DatasetError, Result};

/// One law a scenario fits and the data it needs.
#[derive(Debug, Clone, PartialEq)]
pub struct LawNeed {
    /// The law's name, as `grainlaw fit` and `leave_out` spell it (`mu-i`).
    pub law: &'static str,
    /// The law in one phrase (its formula).
    pub formula: &'static str,
    /// The key of the plan that sets how many points there are (`inertial_numbers`); empty
    /// when the points are known only after the run.
    pub key: &'static str,
    /// Points needed, at least.
    pub needs: usize,
    /// Points the plan gives (`None`: known only after the run).
    pub have: Option<usize>,
    /// Why that many (or, with `have` unknown, what the points are).
    pub why: &'static str,
    /// Fitted only when this other law is left out or refused (`mu-i-linear` for `mu-i`).
    pub instead_of: Option<&'static str>,
}

/// The μ(I), μ(I)-linear and φ(I) needs of a rheology of `n` inertial numbers.
pub fn rheology(n: usize) -> Vec<LawNeed> {
    vec![
        LawNeed {
            law: "mu-i",
            formula: "μ(I) = μ_s + (μ₂ − μ_s)/(1 + I₀/I)",
            key: "inertial_numbers",
            needs: 5,
            have: Some(n),
            why: "3 parameters + 2",
            instead_of: None,
        },
        LawNeed {
            law: "mu-i-linear",
            formula: "μ(I) = μ_s + b I",
            key: "inertial_numbers",
            needs: 4,
            have: Some(n),
            why: "2 parameters + 2",
            instead_of: Some("mu-i"),
        },
        LawNeed {
            law: "phi-i",
            formula: "φ(I) = φ_max − a I",
            key: "inertial_numbers",
            needs: 4,
            have: Some(n),
            why: "2 parameters + 2",
            instead_of: None,
        },
    ]
}

/// The names of the laws of `needs`, comma separated.
fn names(needs: &[LawNeed]) -> String {
    needs.iter().map(|n| n.law).collect::<Vec<_>>().join(", ")
}

/// Checks a plan's `leave_out` against the laws it fits and the data each needs (module
/// documentation): every entry must name one of its laws, once; every law not left out whose
/// points the plan sets must have enough of them. Errors name the key: `leave_out[i]`, or the
/// key that sets the points (`inertial_numbers`), saying what to add or what to leave out.
pub fn check(needs: &[LawNeed], leave_out: &[String]) -> Result<()> {
    for (i, name) in leave_out.iter().enumerate() {
        let key = format!("leave_out[{i}]");
        if !needs.iter().any(|n| n.law == name) {
            return Err(DatasetError::invalid(
                key,
                if needs.is_empty() {
                    format!("`{name}`: this scenario fits no law")
                } else {
                    format!(
                        "`{name}` is not a law this scenario fits (it fits: {})",
                        names(needs)
                    )
                },
            ));
        }
        if leave_out[..i].contains(name) {
            return Err(DatasetError::invalid(
                key,
                format!("`{name}` is listed twice"),
            ));
        }
    }
    let out = |law: &str| leave_out.iter().any(|l| l == law);
    for n in needs {
        let Some(have) = n.have else { continue };
        // a fallback is fitted only when its law is left out (if its law runs, its own need,
        // larger, is checked)
        if out(n.law) || n.instead_of.is_some_and(|of| !out(of)) || have >= n.needs {
            continue;
        }
        let fallback = needs
            .iter()
            .find(|f| f.instead_of == Some(n.law) && !out(f.law))
            .map(|f| {
                format!(
                    " ({} is then fitted instead, {}, from {})",
                    f.law, f.formula, f.needs
                )
            })
            .unwrap_or_default();
        let instead = n
            .instead_of
            .map(|of| format!(", fitted because {of} is left out,"))
            .unwrap_or_default();
        return Err(DatasetError::invalid(
            n.key,
            format!(
                "has {have} value{}: the law {} ({}){instead} needs at least {} ({}): add values, or leave it out with leave_out = [{}\"{}\"]{fallback}",
                if have == 1 { "" } else { "s" },
                n.law,
                n.formula,
                n.needs,
                n.why,
                leave_out
                    .iter()
                    .map(|l| format!("\"{l}\", "))
                    .collect::<String>(),
                n.law,
            ),
        ));
    }
    Ok(())
}

/// The needs as TOML comment lines, for `grainlaw scenarios --show` (none for a scenario that
/// fits no law).
pub fn describe(needs: &[LawNeed]) -> Vec<String> {
    if needs.is_empty() {
        return Vec::new();
    }
    let mut lines = vec![
        "# Laws this scenario fits and the data each needs: a plan short of them is refused".into(),
        "# before the run (exit 2), unless the law is listed in `leave_out`:".into(),
    ];
    for n in needs {
        let when = n
            .instead_of
            .map(|of| format!(", fitted when {of} is left out or refused"))
            .unwrap_or_default();
        lines.push(match n.have {
            Some(have) => format!(
                "#   {} ({}){when}: at least {} {} ({}); this plan: {have}",
                n.law, n.formula, n.needs, n.key, n.why
            ),
            None => format!(
                "#   {} ({}){when}: at least {} {} (known after the run: a refusal then)",
                n.law, n.formula, n.needs, n.why
            ),
        });
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(e: DatasetError) -> String {
        match e {
            DatasetError::Invalid { key, .. } => key,
            other => panic!("{other}"),
        }
    }

    #[test]
    fn a_plan_short_of_a_law_is_refused_unless_it_is_left_out() {
        let l = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert!(check(&rheology(5), &[]).is_ok());
        // 3 inertial numbers: μ(I) needs 5
        let e = check(&rheology(3), &[]).unwrap_err();
        let msg = e.to_string();
        assert_eq!(key(e), "inertial_numbers");
        assert!(msg.contains("mu-i") && msg.contains("at least 5"), "{msg}");
        assert!(msg.contains("leave_out = [\"mu-i\"]"), "{msg}");
        // μ(I) left out: its linear form, from 4, is then the one short
        let e = check(&rheology(3), &l(&["mu-i"])).unwrap_err().to_string();
        assert!(e.contains("mu-i-linear") && e.contains("at least 4"), "{e}");
        // 4 points: μ(I) left out, the linear form and φ(I) fitted
        assert!(check(&rheology(4), &l(&["mu-i"])).is_ok());
        assert!(check(&rheology(1), &l(&["mu-i", "mu-i-linear", "phi-i"])).is_ok());
        // unknown or repeated names
        assert_eq!(
            key(check(&rheology(5), &l(&["mu-j"])).unwrap_err()),
            "leave_out[0]"
        );
        assert_eq!(
            key(check(&rheology(5), &l(&["phi-i", "phi-i"])).unwrap_err()),
            "leave_out[1]"
        );
        assert_eq!(key(check(&[], &l(&["mu-i"])).unwrap_err()), "leave_out[0]");
    }

    #[test]
    fn the_needs_are_described_as_toml_comments() {
        let lines = describe(&rheology(3));
        assert!(lines.iter().all(|l| l.starts_with('#')));
        assert!(
            lines.iter().any(|l| l.contains("mu-i (")
                && l.contains("at least 5 inertial_numbers")
                && l.ends_with("this plan: 3")),
            "{lines:?}"
        );
        assert!(describe(&[]).is_empty());
    }
}
