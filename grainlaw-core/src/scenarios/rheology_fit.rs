//! The μ(I) and φ(I) fits of a rheology (a shear cell's or a simple-shear RVE's points): the
//! fits (the full law, then its linear form when the data do not support it), their curves
//! and 95 % bands on the figures, the summary keys, the printed parameters with their
//! intervals, and the laws exported under their verdicts ([`crate::verdict::export_law`]).
//! One implementation for every scenario that measures μ(I) and φ(I); the figures
//! (`rheology_plot`) are also those of a campaign's merged points (`crate::campaign`).

use identify::law::{GrainScale, Provenance};
use identify::mu_i::{fit_mu_i, fit_mu_i_linear, fit_phi_i, RheologySeries};
use identify::{CalibratedLaw, FitOptions};

use super::common::{delta_band, fit_keys, parameter_lines};
use crate::error::Result;
use crate::output::{OutputDir, Summary};
use crate::plot::xy::{Axis, Band, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::progress::warn;
use crate::verdict::{export_law, Checks, RunVerdict, Verdict};

/// What the fits of a rheology need besides its points.
pub(crate) struct RheologyFit<'a> {
    /// Prefix of the verdict's check names (`shear_cell`, `simple_shear`).
    pub(crate) check_prefix: &'a str,
    /// Appended to the figures' titles.
    pub(crate) title_suffix: &'a str,
    /// Legend of the measured points.
    pub(crate) dem_label: &'a str,
    /// The grains' scale, for the laws' constants.
    pub(crate) grain: GrainScale,
    /// Provenance of the laws.
    pub(crate) provenance: Provenance,
    /// The checks the μ(I) law depends on.
    pub(crate) mu_checks: Checks,
    /// The checks the φ(I) law depends on.
    pub(crate) phi_checks: Checks,
    /// Standard errors of the points as `rheology.csv` holds them (drawn as error bars; None
    /// where the scenario measures none), whatever the fits weigh by.
    pub(crate) std_errors: PointStdErrors,
    /// Each point's own verdict (`point_verdict` of `rheology.csv`): a point not ok is drawn
    /// marked.
    pub(crate) point_verdicts: &'a [Verdict],
    /// The laws the plan leaves out (`mu-i`, `mu-i-linear`, `phi-i`): not fitted.
    pub(crate) leave_out: &'a [String],
}

/// Standard errors of a rheology's points, one per point, each optional.
#[derive(Debug, Clone, Default)]
pub(crate) struct PointStdErrors {
    /// Of `I`.
    pub(crate) i: Option<Vec<f64>>,
    /// Of `μ`.
    pub(crate) mu: Option<Vec<f64>>,
    /// Of `φ`.
    pub(crate) phi: Option<Vec<f64>>,
}

/// One measured point of a rheology figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MeasuredPoint {
    /// Inertial number and its standard error (NaN: none).
    pub(crate) i: f64,
    pub(crate) i_std_error: f64,
    /// The measured value (μ or φ) and its standard error (NaN: none).
    pub(crate) value: f64,
    pub(crate) std_error: f64,
    /// Whether the point passed its own checks.
    pub(crate) passed: bool,
}

/// A fitted law drawn over its data: the legend's formula, whether the law is linear in `I`
/// (then drawn on a linear `I` axis, where it is a straight line; the full μ(I) on a
/// logarithmic one), and its delta-method band `(I, f, lo, hi)` ([`delta_band`]) over the
/// inertial numbers of the points it was fitted to ([`curve_abscissae`]).
#[derive(Debug, Clone)]
pub(crate) struct FittedCurve {
    pub(crate) label: String,
    pub(crate) linear: bool,
    pub(crate) band: Vec<(f64, f64, f64, f64)>,
}

/// A rheology figure: `μ(I)` or `φ(I)`.
pub(crate) struct RheologyFigure<'a> {
    /// Title.
    pub(crate) title: String,
    /// The quantity with its definition, e.g. `μ = |σ_xy| / P`.
    pub(crate) y_label: &'a str,
    /// Colour of the points and of the band.
    pub(crate) colour: plotters::style::RGBColor,
    /// Legend of the points that passed their own checks.
    pub(crate) passed_label: String,
    /// Legend of the others (drawn hollow).
    pub(crate) marked_label: &'a str,
    /// The points.
    pub(crate) points: &'a [MeasuredPoint],
    /// The fitted law, or None when none was fitted.
    pub(crate) curve: Option<FittedCurve>,
    /// Text lines in the plotting area (e.g. why no law is drawn).
    pub(crate) notes: Vec<String>,
}

/// Number of intervals of a drawn curve.
const CURVE_INTERVALS: usize = 80;

/// Abscissae of a fitted curve over the data it was fitted to, `lo ≤ I ≤ hi`: evenly spaced,
/// or geometrically on a logarithmic axis; the curve is not drawn beyond its data.
pub(crate) fn curve_abscissae(lo: f64, hi: f64, log: bool) -> Vec<f64> {
    (0..=CURVE_INTERVALS)
        .map(|k| {
            let t = k as f64 / CURVE_INTERVALS as f64;
            if log {
                lo * (hi / lo).powf(t)
            } else {
                lo + (hi - lo) * t
            }
        })
        .collect()
}

/// The range `[min, max]` of the finite values.
pub(crate) fn finite_range(xs: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    xs.into_iter()
        .filter(|x| x.is_finite())
        .fold(None, |r, x| match r {
            None => Some((x, x)),
            Some((lo, hi)) => Some((lo.min(x), hi.max(x))),
        })
}

/// The figure of a rheology: the points that passed their own checks (filled, with error
/// bars of ± one standard error where one is known), the others hollow under their own
/// legend, the fitted law over its data with its 95 % band; `I` on a linear axis unless the
/// law drawn is not linear in `I` (the full μ(I)).
pub(crate) fn rheology_plot(f: &RheologyFigure<'_>) -> XyPlot {
    let log = f.curve.as_ref().is_some_and(|c| !c.linear);
    let mut x = Axis::new("inertial number I");
    if log {
        x = x.log();
    }
    let mut plot = XyPlot::new(&f.title, x, Axis::new(f.y_label));
    if let Some(c) = &f.curve {
        plot.bands.push(Band::between(
            "95 % confidence band",
            f.colour,
            &c.band.iter().map(|b| (b.0, b.2, b.3)).collect::<Vec<_>>(),
        ));
        plot.series.push(Series::new(
            &c.label,
            Style::Line,
            PALETTE[1],
            c.band.iter().map(|b| (b.0, b.1)).collect(),
        ));
    }
    let pts = |passed: bool| -> Vec<(f64, f64, f64, f64)> {
        f.points
            .iter()
            .filter(|p| p.passed == passed)
            .map(|p| (p.i, p.value, p.i_std_error, p.std_error))
            .collect()
    };
    let with_errors = f
        .points
        .iter()
        .any(|p| p.std_error.is_finite() && p.std_error > 0.0);
    let passed_label = if with_errors {
        format!("{}, ± 1 standard error", f.passed_label)
    } else {
        f.passed_label.clone()
    };
    plot.series.push(Series::with_errors(
        &passed_label,
        Style::Points,
        f.colour,
        pts(true),
    ));
    let marked = pts(false);
    if !marked.is_empty() {
        plot.series.push(Series::with_errors(
            f.marked_label,
            Style::Circles,
            PALETTE[6],
            marked,
        ));
    }
    plot.notes = f.notes.clone();
    plot.legend = LegendAt::UpperLeft;
    plot
}

/// How an accepted fit is shown: its summary-key prefix, the form recorded under
/// `{key}_form` (with `{key}_r_squared`), the formula (legend), the printed title, whether the
/// law is linear in `I`, the name of its law JSON, and the law's value at `I` for parameters
/// `p` (the curve and its band).
struct Shown {
    key: &'static str,
    form: Option<&'static str>,
    formula: &'static str,
    title: &'static str,
    linear: bool,
    file: &'static str,
    model: fn(&[f64], f64) -> f64,
}

/// The fits of μ(I) and φ(I) of one series ([`fit_mu_phi`]): their input and where they write.
struct LawFits<'a, 'b> {
    out: &'a mut OutputDir,
    series: &'a RheologySeries,
    inp: &'a RheologyFit<'b>,
    verdict: &'a mut RunVerdict,
    s: &'a mut Summary,
    headline: &'a mut Vec<String>,
    opts: FitOptions,
    /// The range of the inertial numbers, over which the curves are drawn.
    range: (f64, f64),
}

/// The curve a fit draws (when its law passed) and the notes of its figure.
type LawCurve = (Option<FittedCurve>, Vec<String>);

/// A law that could not be fitted: its check `PREFIX.LAW_fit` (`prefix`, `law` the law's file
/// name, `mu_i` or `phi_i`) refused in the run's verdict with `reason`.
fn refuse_fit(verdict: &mut RunVerdict, prefix: &str, law: &str, reason: String) {
    verdict.run.fail(
        &format!("{prefix}.{law}_fit"),
        Verdict::Refused,
        f64::NAN,
        f64::NAN,
        reason,
    );
}

impl<'b> LawFits<'_, 'b> {
    /// Exports `law` under `checks` as `shown` says, records the summary keys and the printed
    /// parameters (after the line saying the law is rejected, when it is), and returns the
    /// fitted curve with its 95 % band over the range of the fitted points.
    fn record(
        &mut self,
        shown: &Shown,
        law: &CalibratedLaw,
        checks: Checks,
        report: &identify::FitReport,
    ) -> Result<FittedCurve> {
        let exported = export_law(self.out, self.verdict, shown.file, law, checks)?;
        fit_keys(self.s, shown.key, &report.parameters);
        if let Some(form) = shown.form {
            self.s
                .text(&format!("{}_form", shown.key), form)
                .num(&format!("{}_r_squared", shown.key), report.r_squared);
        }
        self.headline.extend(exported.heading(&law.law));
        self.headline.extend(parameter_lines(
            shown.title,
            report.r_squared,
            &report.parameters,
        ));
        let (lo, hi) = self.range;
        let band = delta_band(
            &report.values(),
            &report.covariance,
            report.t_critical,
            &curve_abscissae(lo, hi, !shown.linear),
            shown.model,
        );
        Ok(FittedCurve {
            label: shown.formula.to_string(),
            linear: shown.linear,
            band,
        })
    }

    /// A fit that failed with `error`: the error under `error_key` in the summary, the stale
    /// law `file` (`mu_i`, `phi_i`) removed, its check refused with `reason`.
    fn failed(&mut self, error_key: &str, error: &str, file: &str, reason: String) -> Result<()> {
        self.s.text(error_key, error);
        crate::verdict::remove_stale_law(self.out, file)?;
        refuse_fit(self.verdict, self.inp.check_prefix, file, reason);
        Ok(())
    }

    /// Stage "fit" of μ(I): the full law, or its linear form when the full one is refused or
    /// left out.
    fn mu(&mut self) -> Result<LawCurve> {
        let (series, inp) = (self.series, self.inp);
        let mut mu_notes = Vec::new();
        let left = |law: &str| inp.leave_out.iter().any(|l| l == law);
        // μ(I), or its linear form when μ(I) is refused or left out (`leave_out`)
        let full = if left("mu-i") {
            None
        } else {
            Some(fit_mu_i(series, &self.opts))
        };
        let mut mu_curve = None;
        let linear_reason = match full {
            Some(Ok(f)) => {
                let shown = Shown {
                    key: "mu_i",
                    form: Some("mu-i"),
                    formula: "μ_s + (μ₂ − μ_s)/(1 + I₀/I)",
                    title: "μ(I) = μ_s + (μ₂ − μ_s)/(1 + I₀/I)",
                    linear: false,
                    file: "mu_i",
                    model: |p, i| {
                        identify::laws::mu_i::MuILaw {
                            mu_s: p[0],
                            mu_2: p[1],
                            i0: p[2],
                        }
                        .mu(i)
                    },
                };
                let law = CalibratedLaw::from_mu_i(&f, inp.grain, inp.provenance.clone());
                mu_curve = Some(self.record(&shown, &law, inp.mu_checks.clone(), &f.report)?);
                None
            }
            Some(Err(e)) => {
                self.s.text("mu_i_fit_error", &e.to_string());
                Some(e.to_string())
            }
            None => None,
        };
        let try_linear = linear_reason.is_some() || left("mu-i");
        if try_linear && left("mu-i-linear") {
            // neither form is fitted: the plan said so at the start
            crate::verdict::remove_stale_law(self.out, "mu_i")?;
            mu_notes.push("no μ(I) law fitted (left out by the plan)".into());
            if let Some(e) = linear_reason {
                warn(&format!(
                    "μ(I) fit failed ({e}); its linear form is left out (leave_out)"
                ));
                refuse_fit(
                    self.verdict,
                    inp.check_prefix,
                    "mu_i",
                    format!("no μ(I) law could be fitted: {e}"),
                );
            }
        } else if try_linear {
            let formula = if let Some(e) = &linear_reason {
                warn(&format!(
                    "μ(I) fit failed ({e}); fitting the linear form μ_s + b I"
                ));
                "μ_s + b I (the full μ(I) refused)"
            } else {
                "μ_s + b I (the full μ(I) left out)"
            };
            match fit_mu_i_linear(series, &self.opts) {
                Ok(f) => {
                    let shown = Shown {
                        key: "mu_i",
                        form: Some("mu-i-linear"),
                        formula,
                        title: "μ(I) = μ_s + b I (linear form)",
                        linear: true,
                        file: "mu_i",
                        model: |p, i| p[0] + p[1] * i,
                    };
                    let law =
                        CalibratedLaw::from_mu_i_linear(&f, inp.grain, inp.provenance.clone());
                    mu_curve = Some(self.record(&shown, &law, inp.mu_checks.clone(), &f.report)?);
                }
                Err(e2) => {
                    warn(&format!("linear μ(I) fit failed too: {e2}"));
                    let reason = format!("no μ(I) law could be fitted: {e2}");
                    self.failed("mu_i_linear_fit_error", &e2.to_string(), "mu_i", reason)?;
                    mu_notes.push("no μ(I) law fitted (mu_i_linear_fit_error)".into());
                }
            }
        }
        Ok((mu_curve, mu_notes))
    }

    /// Stage "fit" of φ(I).
    fn phi(&mut self) -> Result<LawCurve> {
        let (series, inp) = (self.series, self.inp);
        let left = |law: &str| inp.leave_out.iter().any(|l| l == law);
        let mut phi_notes = Vec::new();
        let phi_curve = match (!left("phi-i")).then(|| fit_phi_i(series, &self.opts)) {
            // left out by the plan (said at the start)
            None => {
                crate::verdict::remove_stale_law(self.out, "phi_i")?;
                phi_notes.push("no φ(I) law fitted (left out by the plan)".into());
                None
            }
            Some(Ok(f)) => {
                let shown = Shown {
                    key: "phi_i",
                    form: None,
                    formula: "φ_max − a I",
                    title: "φ(I) = φ_max − a I",
                    linear: true,
                    file: "phi_i",
                    model: |p, i| p[0] - p[1] * i,
                };
                let law = CalibratedLaw::from_phi_i(&f, inp.grain, inp.provenance.clone());
                Some(self.record(&shown, &law, inp.phi_checks.clone(), &f.report)?)
            }
            Some(Err(e)) => {
                warn(&format!("φ(I) fit failed: {e}"));
                let reason = format!("the φ(I) fit failed: {e}");
                self.failed("phi_i_fit_error", &e.to_string(), "phi_i", reason)?;
                phi_notes.push("no φ(I) law fitted (phi_i_fit_error)".into());
                None
            }
        };
        Ok((phi_curve, phi_notes))
    }
}

/// Fits μ(I) and φ(I) to `series` (those the plan does not leave out), writes the laws that
/// pass (or their `.rejected.json`), records refusals in `verdict`, the keys in `s`, the printed
/// lines in `headline`; returns the μ(I) and φ(I) figures (`rheology_plot`). Every point
/// enters the fits (a point failing its own checks makes the laws fail theirs).
pub(crate) fn fit_mu_phi(
    out: &mut OutputDir,
    series: &RheologySeries,
    inp: &RheologyFit<'_>,
    verdict: &mut RunVerdict,
    s: &mut Summary,
    headline: &mut Vec<String>,
) -> Result<(XyPlot, XyPlot)> {
    let is = &series.inertial_number;
    let mut fits = LawFits {
        out,
        series,
        inp,
        verdict,
        s,
        headline,
        opts: FitOptions::default(),
        range: finite_range(is.iter().copied()).unwrap_or((0.0, 0.0)),
    };
    let (mu_curve, mu_notes) = fits.mu()?;
    let (phi_curve, phi_notes) = fits.phi()?;
    let points = |values: Option<&[f64]>, se: Option<&[f64]>| -> Vec<MeasuredPoint> {
        let Some(values) = values else {
            return Vec::new();
        };
        let at = |v: Option<&[f64]>, k: usize| v.and_then(|v| v.get(k)).copied();
        is.iter()
            .zip(values)
            .enumerate()
            .map(|(k, (&i, &value))| MeasuredPoint {
                i,
                i_std_error: at(inp.std_errors.i.as_deref(), k).unwrap_or(f64::NAN),
                value,
                std_error: at(se, k).unwrap_or(f64::NAN),
                passed: inp.point_verdicts.get(k) == Some(&Verdict::Ok),
            })
            .collect()
    };
    let marked_label = |fitted: bool| {
        if fitted {
            "failed its own checks (fitted: the law is not calibrated)"
        } else {
            "failed its own checks"
        }
    };
    let mu_points = points(series.mu.as_deref(), inp.std_errors.mu.as_deref());
    let pmu = rheology_plot(&RheologyFigure {
        title: format!("Friction law μ(I){}", inp.title_suffix),
        y_label: "μ = |σ_xy| / P",
        colour: PALETTE[0],
        passed_label: inp.dem_label.to_string(),
        marked_label: marked_label(mu_curve.is_some()),
        points: &mu_points,
        curve: mu_curve,
        notes: mu_notes,
    });
    let phi_points = points(series.phi.as_deref(), inp.std_errors.phi.as_deref());
    let mut pphi = rheology_plot(&RheologyFigure {
        title: format!("Solid fraction φ(I){}", inp.title_suffix),
        y_label: "solid fraction φ",
        colour: PALETTE[2],
        passed_label: inp.dem_label.to_string(),
        marked_label: marked_label(phi_curve.is_some()),
        points: &phi_points,
        curve: phi_curve,
        notes: phi_notes,
    });
    pphi.legend = LegendAt::UpperRight;
    Ok((pmu, pphi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(i: f64, value: f64, se: f64, passed: bool) -> MeasuredPoint {
        MeasuredPoint {
            i,
            i_std_error: f64::NAN,
            value,
            std_error: se,
            passed,
        }
    }

    /// The figure's data: the points that passed carry error bars of their standard errors
    /// (the one without a standard error none), the failed point is in its own hollow series,
    /// a linear law is drawn on a linear I axis over exactly the fitted points' I range, and
    /// the full μ(I) on a logarithmic one.
    #[test]
    fn points_carry_their_errors_and_laws_their_range_and_axis() {
        let pts = [
            point(0.04, 0.33, 0.009, true),
            point(0.1, 0.40, f64::NAN, true),
            point(0.25, 0.53, 0.015, true),
            point(0.07, 0.45, 0.017, false),
        ];
        let (lo, hi) = (0.04, 0.25);
        let law = |linear: bool| FittedCurve {
            label: "law".into(),
            linear,
            band: curve_abscissae(lo, hi, !linear)
                .into_iter()
                .map(|i| (i, 0.3 + i, 0.29 + i, 0.31 + i))
                .collect(),
        };
        let fig = |curve| {
            rheology_plot(&RheologyFigure {
                title: "μ(I)".into(),
                y_label: "μ",
                colour: PALETTE[0],
                passed_label: "DEM".into(),
                marked_label: "failed",
                points: &pts,
                curve: Some(curve),
                notes: Vec::new(),
            })
        };
        let p = fig(law(true));
        assert!(!p.x.log, "a linear law on a linear axis");
        let dem = p
            .series
            .iter()
            .find(|s| s.label.starts_with("DEM"))
            .unwrap();
        assert_eq!(dem.label, "DEM, ± 1 standard error");
        assert_eq!(
            dem.error_bars(),
            vec![(0.04, 0.33, 0.0, 0.009), (0.25, 0.53, 0.0, 0.015)]
        );
        let failed = p.series.iter().find(|s| s.label == "failed").unwrap();
        assert_eq!(failed.style, Style::Circles);
        assert_eq!(failed.xy, vec![(0.07, 0.45)]);
        assert_eq!(failed.error_bars(), vec![(0.07, 0.45, 0.0, 0.017)]);
        let curve = p.series.iter().find(|s| s.label == "law").unwrap();
        let xs: Vec<f64> = curve.xy.iter().map(|q| q.0).collect();
        assert_eq!(xs.first(), Some(&lo));
        assert!((xs.last().unwrap() - hi).abs() <= 1e-15 * hi, "{xs:?}");
        assert!(xs.iter().all(|&x| (lo..=hi * (1.0 + 1e-15)).contains(&x)));
        // evenly spaced on the linear axis: a straight law is drawn straight
        assert!((xs[1] - xs[0] - (hi - lo) / 80.0).abs() < 1e-15);
        let band_x = p.bands[0].outline.iter().map(|q| q.0);
        assert!(band_x.clone().all(|x| x >= lo && x <= hi * (1.0 + 1e-15)));
        let p = fig(law(false));
        assert!(p.x.log, "the full μ(I) on a logarithmic axis");
    }

    /// Without any standard error the legend claims no error bars, and no bar is drawn.
    #[test]
    fn no_error_bars_without_standard_errors() {
        let pts = [
            point(0.01, 0.3, f64::NAN, true),
            point(0.1, 0.4, f64::NAN, true),
        ];
        let p = rheology_plot(&RheologyFigure {
            title: "μ(I)".into(),
            y_label: "μ",
            colour: PALETTE[0],
            passed_label: "DEM".into(),
            marked_label: "failed",
            points: &pts,
            curve: None,
            notes: Vec::new(),
        });
        assert_eq!(p.series.len(), 1);
        assert_eq!(p.series[0].label, "DEM");
        assert!(p.series[0].error_bars().is_empty());
        assert!(!p.x.log);
    }
}
