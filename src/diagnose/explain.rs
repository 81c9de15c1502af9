//! explain — a diagnosis in words: the located residual structure, the
//! verdict's physics and fitted values, why the others are not named, and
//! the cautions a tyre engineer should hear.
//!
//! When nothing is named, the words weigh the structure the residual shows
//! by its size, not only by its significance: on tens of thousands of
//! samples a structure of a few tenths of a per cent of the squared error
//! is significant and still nothing a model could be missing. Below
//! [`MIN_GAIN`] of a channel's squares — the least a candidate must remove
//! to be named — every grouping is reported as small and the verdict reads
//! "Nothing is missing", unless the baseline itself misfits.
//!
//! Must never: call a grouping significant that [`super::locate`] did not,
//! or state a figure the evaluation does not hold.

use super::candidate::{channels_in_words, evidence, why_not, Evaluation, EvidenceGrade, MIN_GAIN};
use super::locate::Finding;
use super::quality::QualityRow;
use crate::residual::Channel;

/// The significant findings of one channel in words ("changes with the
/// sweep direction (rising − falling +41 N) and follows the force rate"),
/// or None when nothing is significant. At most the three strongest (by z;
/// [`locate`](super::locate::locate) ranks them) are named.
pub fn findings_in_words(findings: &[Finding], unit: &str) -> Option<String> {
    let parts: Vec<String> = findings
        .iter()
        .filter(|f| f.significant)
        .take(3)
        .map(|f| {
            let words = finding_in_words(f, unit);
            if f.share.is_finite() {
                format!("{words} [{} % of its squares]", share_in_words(f.share))
            } else {
                words
            }
        })
        .collect();
    match parts.len() {
        0 => None,
        1 => Some(parts[0].clone()),
        n => Some(format!(
            "{} and {}",
            parts[..n - 1].join(", "),
            parts[n - 1]
        )),
    }
}

/// One finding in words, without its size.
fn finding_in_words(f: &Finding, unit: &str) -> String {
    let scale = |what: &str| {
        format!(
            "scales with {what} (force scale error {:+.1} % at {}, {:+.1} % at {})",
            100.0 * f.group("scale_at_min"),
            set_point(f.name, f.group("x_min")),
            100.0 * f.group("scale_at_max"),
            set_point(f.name, f.group("x_max"))
        )
    };
    match f.name {
        "sweep_direction" => format!(
            "changes with the sweep direction (rising − falling {} {unit} at equal slip)",
            sig3(f.group("rising_minus_falling"), true)
        ),
        "force_rate" => {
            let (tau, metres) = (f.group("delay_s"), f.group("delay_m"));
            if tau.is_finite() {
                format!(
                    "follows the force rate (it grows with the slip rate), as a measurement {} by {:.3} s{} would show",
                    if tau >= 0.0 { "late" } else { "early" },
                    tau.abs(),
                    if metres.is_finite() {
                        format!(" ({:.2} m rolled)", metres.abs())
                    } else {
                        String::new()
                    }
                )
            } else {
                "follows the force rate (it grows with the slip rate)".into()
            }
        }
        "time_in_run" => format!(
            "drifts with time in the run ({} {unit}/s, + = measured getting stronger)",
            sig3(f.group("slope_per_s"), true)
        ),
        "slip_region" => {
            let regions = ["linear", "peak", "sliding"];
            let (k, v) = regions
                .iter()
                .map(|r| (*r, f.group(r)))
                .filter(|x| x.1.is_finite())
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .unwrap_or(("linear", 0.0));
            format!(
                "concentrates in the {k} slip region (measured {} than the model by {} {unit} on average)",
                if v >= 0.0 { "stronger" } else { "weaker" },
                sig3(v.abs(), false)
            )
        }
        "load" => scale("load"),
        "inclination" => scale("inclination"),
        "pressure" => scale("pressure"),
        "speed" => scale("speed"),
        "energy" => scale("the accumulated frictional energy"),
        other => format!("depends on {other}"),
    }
}

/// A share in per cent to two significant digits ("0.31", "12").
fn share_in_words(share: f64) -> String {
    let pct = 100.0 * share;
    if pct >= 9.95 {
        format!("{pct:.0}")
    } else if pct >= 0.995 {
        format!("{pct:.1}")
    } else {
        format!("{pct:.2}")
    }
}

/// Whether a significant grouping is large enough to carry a verdict: it
/// accounts for at least [`MIN_GAIN`] of its channel's squared residual (an
/// unknown size counts as large).
fn material(f: &Finding) -> bool {
    f.significant && !(f.share < MIN_GAIN)
}

/// `x` to 3 significant digits (with its sign when `signed`).
pub(crate) fn sig3(x: f64, signed: bool) -> String {
    let d = if x == 0.0 || !x.is_finite() {
        0
    } else {
        (2 - x.abs().log10().floor() as i32).clamp(0, 6) as usize
    };
    if signed {
        format!("{x:+.d$}")
    } else {
        format!("{x:.d$}")
    }
}

/// A set point in engineering units.
fn set_point(grouping: &str, x: f64) -> String {
    match grouping {
        "load" => format!("{x:.0} N"),
        "inclination" => format!("{:.1}°", x.to_degrees()),
        "pressure" => format!("{:.1} kPa", x / 1e3),
        "speed" => format!("{x:.1} m/s"),
        "energy" => format!("{:.0} kJ", x / 1e3),
        _ => format!("{x:.4}"),
    }
}

/// The explanation of the verdict (see the module docs). `not_clean`: the
/// baseline misfits (a channel above [`super::misfit::MISFIT_RATIO`] × its
/// noise floor) or another check names a finding (the slip channel), so
/// that "nothing is missing" must not be said. `unseparable`: a condition
/// that varies with time in the run alone (`time_drift_in_words`); with
/// no verdict, "nothing is missing" is then said only of what the
/// recording can tell apart, and the words say what it cannot.
pub fn explain(
    findings: &[(Channel, Vec<Finding>)],
    verdict: Option<&Evaluation>,
    best_other: Option<&Evaluation>,
    alpha: f64,
    not_clean: bool,
    unseparable: Option<&str>,
) -> String {
    let small = !not_clean && findings.iter().all(|(_, f)| !f.iter().any(material));
    let mut where_ = Vec::new();
    for (ch, f) in findings {
        if let Some(w) = findings_in_words(f, ch.unit()) {
            where_.push(format!("the {} residual {w}", ch.name()));
        }
    }
    let located = if where_.is_empty() {
        None
    } else {
        Some(where_.join("; "))
    };
    match verdict {
        Some(e) => format!(
            "{}. Missing from the model: {}. Fitted: {}. This removes {:.0} % of the baseline's error on held-out segments (each channel's squared error: {}; BIC {:+.1}).{}{}",
            capitalise(located.as_deref().unwrap_or(
                "no single grouping of the residual is significant on its own"
            )),
            e.physics,
            e.describe,
            100.0 * e.oos_gain,
            channels_in_words(e),
            e.delta_bic,
            at_bound_note(e),
            weak_evidence_note(e)
        ),
        None => {
            let best = best_other.map_or("no candidate was evaluated".to_string(), |b| {
                format!(
                    "the best candidate, {}, removes {:.1} % of the held-out error ({}; BIC {:+.1}) and is not named: {}",
                    b.name,
                    100.0 * b.oos_gain,
                    channels_in_words(b),
                    b.delta_bic,
                    // A qualifier is left unnamed only when another
                    // candidate overshadows it, which a later sentence says.
                    why_not(b).unwrap_or_else(|| {
                        "another candidate removes more than twice as much of the same error (see below)".into()
                    })
                )
            });
            let nothing = if unseparable.is_some() {
                "Nothing is missing that this recording can tell apart"
            } else {
                "Nothing is missing"
            };
            let words = match located {
                None => format!(
                    "{nothing}: the residual is noise (no grouping significant at {:.0} % family-wise) and {best}.",
                    100.0 * alpha
                ),
                Some(w) if small => format!(
                    "{nothing}: the structure the residual shows is real but small — {w} — each part under the {:.1} % of its channel's squares that a candidate must remove to be named, and {best}.",
                    100.0 * MIN_GAIN
                ),
                Some(w) => format!(
                    "{}, but none of the candidates explains it: {best}. The structure is real but lies outside the candidate physics (or in the baseline's own fit).",
                    capitalise(&w)
                ),
            };
            match unseparable {
                Some(u) => format!("{words} {}", capitalise(u)),
                None => words,
            }
        }
    }
}

/// How much longer one lateral channel's delay must be than the other's
/// for [`one_channel_lag`] to speak (3×: the two delays of a relaxation
/// differ by far less; a filter on one channel gives the other none).
pub const LAG_RATIO: f64 = 3.0;

/// A delay in Fy or Mz alone, in words, or None. The tyre's relaxation acts
/// on the slip angle that Fy and Mz share (Pacejka, *Tyre and Vehicle
/// Dynamics*, 3rd ed., §7.2: both follow the deflection slip α′), so it
/// delays both; when one channel's residual follows the force rate by a
/// material share ([`MIN_GAIN`]) as a delay more than [`LAG_RATIO`] times
/// the other's, the delay points at the measurement of that channel (its
/// filter or time alignment) rather than at the tyre — a steady or
/// transient tyre model should not follow it.
pub fn one_channel_lag(findings: &[(Channel, Vec<Finding>)]) -> Option<String> {
    let lag = |c: Channel| {
        findings
            .iter()
            .find(|(ch, _)| *ch == c)
            .and_then(|(_, f)| f.iter().find(|x| x.name == "force_rate"))
    };
    let (fy, mz) = (lag(Channel::Fy)?, lag(Channel::Mz)?);
    let words = |late: &Finding, other: &Finding, a: Channel, b: Channel| {
        let (t, o) = (late.group("delay_s"), other.group("delay_s"));
        (material(late) && t > 0.0 && o.is_finite() && t > LAG_RATIO * o.abs()).then(|| {
            let m = late.group("delay_m");
            format!(
                "Only {} lags: by {:.3} s{}, {} by {:+.3} s. The tyre's relaxation delays the slip angle that Fy and Mz share, so it would delay both; a delay in one channel alone points at the measurement (that channel's filter or time alignment) rather than at the tyre, and no tyre model should follow it.",
                a.name(),
                t,
                if m.is_finite() {
                    format!(" ({m:.2} m rolled)")
                } else {
                    String::new()
                },
                b.name(),
                o
            )
        })
    };
    words(mz, fy, Channel::Mz, Channel::Fy).or_else(|| words(fy, mz, Channel::Fy, Channel::Mz))
}

/// What a recording cannot tell apart, in words: the recorded inflation
/// pressure that rises (or falls) with the run alone (`factor::drift_with_time`):
/// a dependence on it is then indistinguishable from any other slow drift.
pub fn time_drift_in_words(d: &super::factor::TimeDrift) -> String {
    let (a, b, how) = if d.r >= 0.0 {
        (d.from, d.to, "rises")
    } else {
        (d.to, d.from, "falls")
    };
    format!(
        "the recorded inflation pressure {how} {:.1} → {:.1} kPa with the run alone (correlation {:.2} of its segment means with time), so a dependence on pressure cannot be told from any other slow drift (temperature, wear): a pressure effect may be present though none is named.",
        a / 1e3,
        b / 1e3,
        d.r
    )
}

/// What a recording with gaps in its time cannot follow, in words
/// (`factor::missing_time`: `gap` s missing, `share` of the run).
pub fn missing_time_in_words(gap: f64, share: f64) -> String {
    format!(
        "{gap:.0} s of the run ({:.0} %) are not in the data (rows dropped on loading or not recorded: see `tyrekit data summary`), so an effect that builds up over the run (tread temperature, wear) cannot be followed across those gaps: it may be present though none is named.",
        100.0 * share
    )
}

/// " PPY3 = -3 (its lower bound) is at a bound of its range: …", or "".
pub(crate) fn at_bound_note(e: &Evaluation) -> String {
    if e.at_bound.is_empty() {
        return String::new();
    }
    format!(
        " {} at a bound of the range the candidate allows: the data push beyond it, so that value is a limit, not an estimate.",
        e.at_bound.join(", ")
    )
}

/// A caution when the verdict rests on weak evidence ([`evidence`]: the
/// channel that carries it lowers its BIC by 2 or less, "not worth more
/// than a bare mention" on Kass & Raftery's scale); empty otherwise.
pub(crate) fn weak_evidence_note(e: &Evaluation) -> String {
    match evidence(e) {
        Some(w) if w.grade == EvidenceGrade::Weak => format!(
            " The evidence is weak: the channel that carries it, {}, lowers its BIC by only {:.1} (2 or less is \"not worth more than a bare mention\" on Kass & Raftery's scale), so the name rests on a small held-out gain; a repeat of the run, or a longer programme, would confirm or refute it.",
            w.channel.name(),
            w.bic_fall
        ),
        _ => String::new(),
    }
}

/// Relative rise of a channel's held-out σ above which the verdict's
/// explanation carries a caution (10 %: well above the run-to-run scatter
/// of σ between the halves, far below what a real improvement shows).
pub const WORSE: f64 = 0.10;

/// A caution when the verdict's model makes a channel's held-out fit worse
/// by more than [`WORSE`] (relative σ) while others gain: a tyre engineer
/// would then suspect the gain comes from another misfit of the baseline
/// that the extension happens to absorb, not from the named physics.
pub fn caution(out_of_sample: &[QualityRow]) -> Option<String> {
    let all: Vec<&QualityRow> = out_of_sample
        .iter()
        .filter(|r| r.condition == "all" && r.sigma_before.is_finite() && r.sigma_after.is_finite())
        .collect();
    let worse: Vec<String> = all
        .iter()
        .filter(|r| r.sigma_after > (1.0 + WORSE) * r.sigma_before)
        .map(|r| {
            format!(
                "{} (held-out σ {:.2} % → {:.2} %)",
                r.channel.name(),
                100.0 * r.sigma_before,
                100.0 * r.sigma_after
            )
        })
        .collect();
    if worse.is_empty() {
        return None;
    }
    let better: Vec<&str> = all
        .iter()
        .filter(|r| r.sigma_after < r.sigma_before)
        .map(|r| r.channel.name())
        .collect();
    Some(format!(
        "Caution: it makes {} worse{}; the verdict is doubtful — the gain may be another misfit of the baseline that this extension absorbs.",
        worse.join(" and "),
        if better.is_empty() {
            String::new()
        } else {
            format!(", the gain comes from {} alone", better.join(" and "))
        }
    ))
}

pub(crate) fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or(String::new(), |f| {
        f.to_uppercase().collect::<String>() + c.as_str()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A significant force-rate finding of the given size on Fy.
    fn lag(share: f64) -> Vec<(Channel, Vec<Finding>)> {
        vec![(
            Channel::Fy,
            vec![Finding {
                name: "force_rate",
                statistic: share,
                z: 16.0,
                p_value: 0.001,
                p_adjusted: 0.009,
                significant: true,
                detail: String::new(),
                groups: Vec::new(),
                share,
            }],
        )]
    }

    /// The dev set's controls show a significant lag signature of 0.2–0.7 %
    /// of the squares: that reads "Nothing is missing" with its size; a
    /// structure of 5 % — more than a named candidate must remove — reads
    /// as structure outside the candidates; so does a small one where the
    /// baseline misfits, or one whose size is unknown.
    #[test]
    fn a_small_structure_is_nothing_missing_and_a_large_one_is_not() {
        let small = explain(&lag(0.0027), None, None, 0.05, false, None);
        assert!(small.starts_with("Nothing is missing"), "{small}");
        assert!(small.contains("[0.27 % of its squares]"), "{small}");
        let large = explain(&lag(0.05), None, None, 0.05, false, None);
        assert!(
            large.starts_with("The Fy residual follows the force rate"),
            "{large}"
        );
        assert!(large.contains("outside the candidate physics"), "{large}");
        assert!(large.contains("[5.0 % of its squares]"), "{large}");
        let misfit = explain(&lag(0.0027), None, None, 0.05, true, None);
        assert!(!misfit.contains("Nothing is missing"), "{misfit}");
        let unknown = explain(&lag(f64::NAN), None, None, 0.05, false, None);
        assert!(!unknown.contains("Nothing is missing"), "{unknown}");
        assert!(!unknown.contains("% of its squares"), "{unknown}");
    }

    /// A verdict that rests on a channel whose BIC falls by 2 or less says
    /// the evidence is weak, with the channel and the fall; one that falls
    /// by 9 does not.
    #[test]
    fn a_verdict_on_weak_evidence_says_so() {
        use crate::diagnose::candidate::ChannelScore;
        let verdict = |bic: f64| Evaluation {
            name: "thermal".into(),
            n_params: 5,
            oos_gain: 0.02,
            fit_gain: 0.03,
            delta_bic: 18.8,
            channels: vec![ChannelScore {
                channel: Channel::Mz,
                n: 20000,
                oos_gain: 0.033,
                fit_gain: 0.079,
                delta_bic: bic,
                baseline_misfit: None,
                reference_gain: 0.0,
                acts: true,
                bic_needed: 0.0,
            }],
            parameters: vec![],
            at_bound: vec![],
            physics: "a tread temperature".into(),
            describe: "a heat capacity".into(),
            reference_gain: 0.0,
            rank_bic: 18.8,
        };
        let weak = explain(&lag(0.0027), Some(&verdict(-0.6)), None, 0.05, false, None);
        assert!(
            weak.contains(
                "The evidence is weak: the channel that carries it, Mz, lowers its BIC by only 0.6"
            ),
            "{weak}"
        );
        let strong = explain(&lag(0.0027), Some(&verdict(-9.0)), None, 0.05, false, None);
        assert!(
            strong.contains("Missing from the model: a tread temperature"),
            "{strong}"
        );
        assert!(!strong.contains("evidence is weak"), "{strong}");
    }

    /// A pressure that drifts with time alone: nothing named is said only
    /// of what the recording can tell apart, with the drift in kPa.
    #[test]
    fn a_pressure_drifting_with_time_qualifies_nothing_missing() {
        let d = crate::diagnose::factor::TimeDrift {
            from: 243.1e3,
            to: 248.9e3,
            r: 0.98,
        };
        let w = time_drift_in_words(&d);
        let small = explain(&lag(0.0027), None, None, 0.05, false, Some(&w));
        assert!(
            small.starts_with("Nothing is missing that this recording can tell apart:"),
            "{small}"
        );
        assert!(small.contains("rises 243.1 → 248.9 kPa"), "{small}");
        assert!(
            small.contains("may be present though none is named"),
            "{small}"
        );
        let falling = time_drift_in_words(&crate::diagnose::factor::TimeDrift { r: -0.95, ..d });
        assert!(falling.contains("falls 248.9 → 243.1 kPa"), "{falling}");
    }

    /// A force-rate finding of `ch` whose residual is that of a delay of
    /// `tau` s (at 16 m/s), with its size and significance.
    fn delayed(ch: Channel, tau: f64, share: f64, significant: bool) -> (Channel, Vec<Finding>) {
        (
            ch,
            vec![Finding {
                name: "force_rate",
                statistic: share,
                z: if significant { 16.0 } else { 0.5 },
                p_value: if significant { 0.001 } else { 0.4 },
                p_adjusted: if significant { 0.009 } else { 1.0 },
                significant,
                detail: String::new(),
                groups: vec![("delay_s".into(), tau), ("delay_m".into(), 16.0 * tau)],
                share,
            }],
        )
    }

    /// A tyre's relaxation delays Fy and Mz alike (the dev set's relaxation
    /// recordings: Mz 1.2–1.4× Fy's delay): nothing said. Mz late by
    /// 0.12 s with a third of its squares while Fy shows none (as the real
    /// TyreData.csv): the measurement is named, with the figures. The same
    /// delay in Mz at 0.5 % of its squares (not material) or not
    /// significant: nothing said.
    #[test]
    fn a_delay_in_one_lateral_channel_alone_is_called_a_measurement_lag() {
        let both = [
            delayed(Channel::Fy, 0.021, 0.25, true),
            delayed(Channel::Mz, 0.028, 0.25, true),
        ];
        assert_eq!(one_channel_lag(&both), None);
        let mz = [
            delayed(Channel::Fy, -0.011, 0.02, false),
            delayed(Channel::Mz, 0.116, 0.34, true),
        ];
        let w = one_channel_lag(&mz).expect("Mz alone lags");
        assert!(
            w.starts_with("Only Mz lags: by 0.116 s (1.86 m rolled), Fy by -0.011 s."),
            "{w}"
        );
        assert!(w.contains("measurement"), "{w}");
        let fy = [
            delayed(Channel::Fy, 0.09, 0.2, true),
            delayed(Channel::Mz, 0.01, 0.1, true),
        ];
        assert!(one_channel_lag(&fy)
            .expect("Fy alone lags")
            .starts_with("Only Fy lags"));
        let small = [
            delayed(Channel::Fy, 0.0, 0.02, false),
            delayed(Channel::Mz, 0.116, 0.005, true),
        ];
        assert_eq!(one_channel_lag(&small), None);
        let noise = [
            delayed(Channel::Fy, 0.0, 0.02, false),
            delayed(Channel::Mz, 0.116, 0.34, false),
        ];
        assert_eq!(one_channel_lag(&noise), None);
        assert_eq!(
            one_channel_lag(&mz[1..]),
            None,
            "without Fy nothing to compare"
        );
    }
}
