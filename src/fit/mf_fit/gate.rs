//! gate — a later stage must not spoil what an earlier one fitted
//! (issue #14 item 3): the combined-slip stage's result is compared, on the
//! judged rows (held out where `--holdout` keeps some), with the tyre before
//! it, with the result after the pure stages were re-polished under the
//! new combined weights, and with that result after pure Fy and the
//! lateral combined weights were polished together ([`joint_fy`]: the
//! stages alone stop where each group is best given the other) — scored on
//! every kind of row the stage fits: the combined ones and both pure kinds,
//! each channel on all of them; the candidate kept is the best one that
//! does not raise any pure-slip channel's error (else the best-scoring of
//! all, the tyre before included).
//!
//! Must never: pick by the fitted rows' cost when held-out rows exist, keep
//! a candidate that raises a pure-slip channel's judged error beyond
//! [`TOL`] while a candidate that does not exists, or print.

use super::{run_stage, StageCtx, StageRun};
use crate::data::SegmentKind;
use crate::fit::mf_stages::{
    conditions_of, fit_stage, gather, stage_params, Channel, StageData, StageKind, COARSE_SAMPLES,
    START_ITERATIONS,
};
use crate::fit::problem::Param;
use crate::fit::solve::{FitOutcome, ProgressFn};
use crate::mf::Model;
use crate::tir::TyreParams;
use std::ops::Range;

/// Relative rise of a pure channel's judged mean-square error still taken
/// as "not raised": 2 % in mean square is 1 % in NRMSE, a tenth of the
/// margin of issue #14's 1.15× goal, below which a decision between
/// candidates is not worth a worse all-row fit.
pub const TOL: f64 = 0.02;

/// The segments a channel's pure-slip error is judged on.
fn pure_kind(c: Channel) -> SegmentKind {
    if c == Channel::Fx {
        SegmentKind::PureLongitudinal
    } else {
        SegmentKind::PureLateral
    }
}

/// Per channel: (Σ residual², Σ measured²) over `kind` rows of `rows`.
fn errors(
    ctx: &StageCtx,
    tyre: &TyreParams,
    rows: &[Vec<Range<usize>>],
    kind: SegmentKind,
    channels: &[Channel],
) -> Vec<(f64, f64)> {
    let model = Model::new(tyre.p.clone(), ctx.form);
    let mut acc = vec![(0.0, 0.0); channels.len()];
    for (r, rec) in ctx.recs.iter().enumerate() {
        for seg in rec.segments.iter().filter(|s| s.kind == kind) {
            for rg in &rows[r] {
                let (a, b) = (
                    seg.start.max(rg.start),
                    seg.end.min(rg.end).min(rec.samples.len()),
                );
                for s in rec.samples.get(a..b).unwrap_or(&[]) {
                    let usable = s.fz > 0.0
                        && [s.fz, s.vx, s.kappa, s.alpha, s.gamma]
                            .iter()
                            .all(|v| v.is_finite());
                    if !usable {
                        continue;
                    }
                    let sol = model.solve(&conditions_of(&tyre.p, s));
                    for (k, c) in channels.iter().enumerate() {
                        let y = c.measured(s);
                        let e = c.of(&sol) - y;
                        if e.is_finite() {
                            acc[k].0 += e * e;
                            acc[k].1 += y * y;
                        }
                    }
                }
            }
        }
    }
    acc
}

/// Judged figures of one candidate.
struct Judged {
    /// Per channel: mean-square error on its pure rows.
    pure: Vec<f64>,
    /// Σ over channels of Σe²/Σy² on the combined rows and both kinds of
    /// pure rows together: the combined stage's own objective on the judged
    /// rows (its weights act on Fy and Mz of the drive/brake sweeps at α = 0
    /// too — κ-induced side force SVyκ, Gyκ — and on Fx of the lateral ones).
    score: f64,
}

fn judge(
    ctx: &StageCtx,
    tyre: &TyreParams,
    rows: &[Vec<Range<usize>>],
    channels: &[Channel],
) -> Judged {
    let comb = errors(ctx, tyre, rows, SegmentKind::Combined, channels);
    let lat = errors(ctx, tyre, rows, SegmentKind::PureLateral, channels);
    let lon = errors(ctx, tyre, rows, SegmentKind::PureLongitudinal, channels);
    let mut pure = Vec::new();
    let mut score = 0.0;
    for (k, &c) in channels.iter().enumerate() {
        let p = if pure_kind(c) == SegmentKind::PureLongitudinal {
            lon[k]
        } else {
            lat[k]
        };
        pure.push(p.0);
        let den = lat[k].1 + lon[k].1 + comb[k].1;
        if den > 0.0 {
            score += (lat[k].0 + lon[k].0 + comb[k].0) / den;
        }
    }
    Judged { pure, score }
}

/// The rule: among the candidates that raise no pure channel's judged
/// error beyond [`TOL`], the least score; when every candidate raises one,
/// the least score among them and the tyre before (`j0`) — the move is then
/// kept only where the held-out error over the stage's rows proves it
/// better. `None`: keep the tyre before.
fn choose(j0: &Judged, cands: &[&Judged]) -> Option<usize> {
    let ok = |j: &Judged| {
        j.pure
            .iter()
            .zip(&j0.pure)
            .all(|(a, b)| *a <= b * (1.0 + TOL) || *b == 0.0)
    };
    let least = |f: &dyn Fn(&Judged) -> bool| {
        cands
            .iter()
            .enumerate()
            .filter(|(_, j)| f(j))
            .min_by(|a, b| a.1.score.total_cmp(&b.1.score))
            .map(|(i, j)| (i, j.score))
    };
    match least(&ok) {
        Some((i, _)) => Some(i),
        None => least(&|_| true)
            .filter(|(_, s)| *s < j0.score)
            .map(|(i, _)| i),
    }
}

/// Decide the combined stage: candidates `after` (the stage's result,
/// `combined` its outcome), `after` with the `pure` stages re-polished from
/// its values, and that with pure Fy and the lateral weights polished
/// together ([`joint_fy`]); `before` the tyre the stage started from.
/// Returns the kept tyre, the outcomes of the re-polish (and joint polish)
/// when it is kept, and a line saying what was kept and why.
#[allow(clippy::too_many_arguments)]
pub(crate) fn accept_combined(
    ctx: &StageCtx,
    before: &TyreParams,
    after: TyreParams,
    combined: &FitOutcome,
    pure: &[StageKind],
    channels: &[Channel],
    rows: &[Vec<Range<usize>>],
    mut progress: Option<&mut ProgressFn>,
) -> crate::Result<(TyreParams, Vec<FitOutcome>, String)> {
    let mut polished = after.clone();
    let mut outs = Vec::new();
    for &k in pure {
        if let StageRun::Done { out: o, .. } =
            run_stage(ctx, k, &polished, false, progress.as_deref_mut())?
        {
            for p in &o.params {
                polished.set(&p.name, p.value)?;
            }
            outs.push(o);
        }
    }
    let joint = joint_fy(ctx, &polished, combined, &outs, progress)?;
    // Each candidate: its name, its tyre and the outcomes kept with it.
    let joint = joint.map(|(t, o)| {
        let all: Vec<FitOutcome> = outs.iter().cloned().chain(o).collect();
        ("combined + joint Fy polish", t, all)
    });
    let mut cands = vec![
        ("combined", after, Vec::new()),
        ("combined + pure re-polish", polished, outs),
    ];
    cands.extend(joint);
    let j0 = judge(ctx, before, rows, channels);
    let judged: Vec<Judged> = cands
        .iter()
        .map(|(_, t, _)| judge(ctx, t, rows, channels))
        .collect();
    let pick = choose(&j0, &judged.iter().collect::<Vec<_>>());
    let figures = |j: &Judged| {
        let v: Vec<String> = channels
            .iter()
            .zip(&j.pure)
            .zip(&j0.pure)
            .map(|((c, a), b)| format!("{} {:.3}", c.name(), if *b > 0.0 { a / b } else { 1.0 }))
            .collect();
        format!("pure MSE/before [{}], score {:.4}", v.join(", "), j.score)
    };
    let detail: Vec<String> = cands
        .iter()
        .zip(&judged)
        .map(|((n, _, _), j)| format!("{n}: {}", figures(j)))
        .collect();
    let note = |kept: &str| {
        format!(
            "combined stage: kept {kept} (judged on {} rows; before: score {:.4}; {})",
            if std::ptr::eq(rows, ctx.train) {
                "fitted"
            } else {
                "held-out"
            },
            j0.score,
            detail.join("; ")
        )
    };
    Ok(match pick {
        Some(i) => {
            let (name, t, o) = cands.swap_remove(i);
            (t, o, note(name))
        }
        None => (
            before.clone(),
            Vec::new(),
            note("the tyre before it (its judged score is the least)"),
        ),
    })
}

/// Lateral combined-slip coefficients (Gyκ and SVyκ, 4.E58–4.E67) that
/// act on the pure cornering rows through their small κ.
fn lateral_weight(name: &str) -> bool {
    ["rby", "rcy", "rey", "rhy", "rvy"]
        .iter()
        .any(|p| name.starts_with(p))
}

/// Whether the stage fitted `p` (inside its bounds or on one), not held it.
fn moved(p: &crate::fit::solve::ParamResult) -> bool {
    use crate::fit::solve::ParamStatus;
    matches!(p.status, ParamStatus::Fitted | ParamStatus::AtBound)
}

/// Pure Fy and the lateral combined weights polished together on the
/// cornering and the combined rows (Fy only), then Mz's free coefficients
/// polished beneath them when the pure stages fitted Mz — both on a
/// subsample of at most [`COARSE_SAMPLES`] rows (a candidate: the gate
/// judges it on every judged row). The stages fit these two groups in
/// turn, and on the pure cornering rows they are coupled: κ there is not 0
/// (±0.5 % at 10° of slip angle on the dev set's r04, from the wheel-plane
/// slip of a belt-referred speed), and with a load-dependent Gyκ shift
/// (RHY2) the weights bend the pure curve at the highest load; each group
/// then sits at the minimum given the other — a point of the alternation,
/// not of the joint cost (r04: pure Fy cost 10 % above the joint minimum,
/// PKY4 pinned on its bound). `None` when the pure Fy stage did not run.
fn joint_fy(
    ctx: &StageCtx,
    tyre: &TyreParams,
    combined: &FitOutcome,
    repolished: &[FitOutcome],
    mut progress: Option<&mut ProgressFn>,
) -> crate::Result<Option<(TyreParams, Vec<FitOutcome>)>> {
    let free_in = |kind: StageKind| -> Vec<&str> {
        repolished
            .iter()
            .filter(|o| o.stage == kind.name())
            .flat_map(|o| o.params.iter().filter(|p| moved(p)))
            .map(|p| p.name.as_str())
            .collect()
    };
    let mut names = free_in(StageKind::PureFy);
    if names.is_empty() {
        return Ok(None);
    }
    names.extend(
        combined
            .params
            .iter()
            .filter(|p| moved(p) && lateral_weight(&p.name))
            .map(|p| p.name.as_str()),
    );
    let steps = [
        (
            "joint Fy",
            Channel::Fy,
            names,
            &[SegmentKind::PureLateral, SegmentKind::Combined][..],
        ),
        (
            "joint Fy: Mz",
            Channel::Mz,
            free_in(StageKind::Mz),
            &[SegmentKind::PureLateral][..],
        ),
    ];
    let mut t = tyre.clone();
    let mut outs = Vec::new();
    for (name, ch, names, kinds) in steps {
        let params: Vec<Param> = [StageKind::PureFy, StageKind::Mz, StageKind::Combined]
            .iter()
            .flat_map(|&k| stage_params(k, &t.p, false, false))
            .filter(|p| names.contains(&p.name.as_str()))
            .collect();
        let mut data = StageData {
            meas: vec![Vec::new()],
            ..Default::default()
        };
        for &k in kinds {
            data.append(gather(&t.p, ctx.recs, Some(ctx.train), k, &[ch]));
        }
        if params.is_empty() || data.conds.len() < ctx.opts.min_samples {
            continue;
        }
        let mut data = data.every(data.conds.len() / COARSE_SAMPLES);
        data.grid = Some(ctx.grid.clone());
        // A candidate's budget: the iterations a start gets in the race
        // (the gate judges where it stands; on the 250 Hz rig recording
        // of `tyrekit bench fit` it was still crawling after 139 steps).
        let mut opts = ctx.opts.fit.clone();
        opts.coarse_first = false;
        opts.lm.max_iter = opts.lm.max_iter.min(START_ITERATIONS);
        let out = fit_stage(
            ctx.form,
            &t.p,
            &params,
            &data,
            &[ch],
            ctx.opts.threads,
            &opts,
            name,
            progress.as_deref_mut(),
            &[],
        )?;
        for p in &out.params {
            t.set(&p.name, p.value)?;
        }
        outs.push(out);
    }
    Ok(Some((t, outs)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn j(pure: &[f64], score: f64) -> Judged {
        Judged {
            pure: pure.to_vec(),
            score,
        }
    }

    /// r04/r07 of the dev set gave these shapes: the stage alone raises
    /// pure Mz (×2.2, ×3.1 in mean square) at a better score; the re-polish
    /// keeps the pure rows. The rule must take the re-polish, not the
    /// lowest score; and when both raise a pure channel, the lowest score
    /// only if it beats the tyre before.
    #[test]
    fn a_stage_may_not_spoil_the_pure_rows() {
        let before = j(&[1.0, 1.0, 1.0], 0.37);
        let stage = j(&[0.98, 1.06, 2.16], 0.030);
        let polished = j(&[1.0, 0.99, 0.91], 0.036);
        assert_eq!(choose(&before, &[&stage, &polished]), Some(1));
        // Both raise Fy: the better score wins if it beats the tyre before…
        let polished = j(&[1.0, 1.09, 0.94], 0.0081);
        let before = j(&[1.0, 1.0, 1.0], 0.0084);
        let stage = j(&[1.0, 1.15, 3.05], 0.0216);
        assert_eq!(choose(&before, &[&stage, &polished]), Some(1));
        // …and the tyre before is kept when it scores best.
        let before = j(&[1.0, 1.0, 1.0], 0.0080);
        assert_eq!(choose(&before, &[&stage, &polished]), None);
        // A rise within TOL is not a rise.
        let before = j(&[1.0], 1.0);
        assert_eq!(choose(&before, &[&j(&[1.0 + 0.5 * TOL], 0.5)]), Some(0));
    }
}
