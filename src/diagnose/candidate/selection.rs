//! selection — the verdict rule (see the module docs of [`super`]): which
//! evaluated candidate qualifies as a named effect, which one wins, and why
//! the others are not named, in words.
//!
//! Must never: name an effect that makes any channel's held-out error worse
//! by more than [`MAX_LOSS`], or one whose best channel gains no more than
//! [`MIN_GAIN`].

use super::{Evaluation, Fitted};

/// Smallest held-out gain (share of the baseline's held-out squared error
/// removed) in at least one channel that names an effect: below it the
/// improvement is within what refitting noise gives (controls of the proof
/// measure < 1 % pooled, < 2 % in any channel).
pub const MIN_GAIN: f64 = 0.05;
/// Largest held-out loss (relative rise of a channel's own held-out SSE)
/// a named effect may cause in any channel with data: as large as the
/// smallest gain that names an effect ([`MIN_GAIN`]) — a change below it is
/// within what refitting noise does to a channel either way; a larger loss
/// means the candidate trades one channel's fit for another's (real
/// TyreData: a 2.7 m relaxation length halves Fy's accuracy to gain on the
/// badly fitted Mz), which no missing physics does.
pub const MAX_LOSS: f64 = 0.05;

/// Whether an evaluation qualifies as a verdict (see [`select`]).
pub fn qualifies(e: &Evaluation) -> bool {
    let (best, worst) = e.channel_range();
    e.name != "none"
        && e.n_params > 0
        && best > MIN_GAIN
        && worst >= -MAX_LOSS
        && e.oos_gain > 0.0
        && e.fit_gain > 0.0
        && e.delta_bic < 0.0
}

/// The verdict (see the module docs): the index in `ev` of the named effect,
/// or None for `none`. A candidate qualifies ([`qualifies`]) when it
/// generalises — some channel's held-out error falls by more than
/// [`MIN_GAIN`] (an effect may live in one channel: a rolling radius in Fx
/// only), no channel's rises by more than [`MAX_LOSS`], the pooled held-out
/// and in-sample gains are positive — and its BIC falls; among those the
/// lowest BIC wins (parsimony between physics that generalise alike, e.g.
/// relaxation against LuGre on a lag: the held-out gains differ by a few %
/// where the extra parameter buys them).
pub fn select(ev: &[(Evaluation, Box<dyn Fitted>)]) -> Option<usize> {
    ev.iter()
        .enumerate()
        .filter(|(_, (e, _))| qualifies(e))
        .min_by(|a, b| a.1 .0.delta_bic.total_cmp(&b.1 .0.delta_bic))
        .map(|(i, _)| i)
}

/// The held-out change of each channel's squared error in words
/// ("Fy −5.4 %, Mz −6.4 %"; − = better).
pub fn channels_in_words(e: &Evaluation) -> String {
    e.channels
        .iter()
        .map(|c| format!("{} {:+.1} %", c.channel.name(), -100.0 * c.oos_gain))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Why `e` is not a verdict ([`qualifies`]), in words; None when it qualifies.
pub fn why_not(e: &Evaluation) -> Option<String> {
    if qualifies(e) {
        return None;
    }
    if e.n_params == 0 {
        return Some(
            "it has nothing to fit: no channel it acts on is recorded, or the condition it acts through (pressure, inclination) has one level only"
                .into(),
        );
    }
    let (best, worst) = e.channel_range();
    let worse: Vec<String> = e
        .channels
        .iter()
        .filter(|c| c.oos_gain < -MAX_LOSS)
        .map(|c| format!("{} {:.1} % worse", c.channel.name(), -100.0 * c.oos_gain))
        .collect();
    Some(if worst < -MAX_LOSS {
        format!(
            "it makes a channel's held-out error worse ({}; at most {:.0} % is allowed)",
            worse.join(", "),
            100.0 * MAX_LOSS
        )
    } else if !(best > MIN_GAIN) {
        format!(
            "no channel's held-out error falls by more than {:.0} %",
            100.0 * MIN_GAIN
        )
    } else if !(e.oos_gain > 0.0 && e.fit_gain > 0.0) {
        "the channels together do not gain both in and out of sample".into()
    } else {
        format!("its BIC rises ({:+.1})", e.delta_bic)
    })
}

#[cfg(test)]
mod tests {
    use super::super::ChannelScore;
    use super::*;
    use crate::residual::Channel;

    fn ev(gains: &[(Channel, f64)], pooled: f64, bic: f64) -> Evaluation {
        Evaluation {
            name: "x".into(),
            n_params: 2,
            oos_gain: pooled,
            fit_gain: pooled,
            delta_bic: bic,
            channels: gains
                .iter()
                .map(|&(channel, g)| ChannelScore {
                    channel,
                    n: 1000,
                    oos_gain: g,
                    fit_gain: g,
                })
                .collect(),
            parameters: vec![],
            at_bound: vec![],
            physics: String::new(),
            describe: String::new(),
        }
    }

    /// The real-data case of the old rule: a large gain on the badly fitted
    /// Mz bought with a worse Fy does not name an effect, however the
    /// pooled number and the BIC look.
    #[test]
    fn a_channel_made_worse_disqualifies() {
        let e = ev(&[(Channel::Fy, -0.56), (Channel::Mz, 0.31)], 0.2, -8.0);
        assert!(!qualifies(&e));
        assert!(why_not(&e).unwrap().contains("Fy"));
    }

    /// An effect that lives in one channel (a rolling radius in Fx) is
    /// named on that channel's gain; the others within the loss tolerance.
    #[test]
    fn one_channel_gain_names_an_effect() {
        let e = ev(
            &[(Channel::Fx, 0.3), (Channel::Fy, 0.0), (Channel::Mz, -0.01)],
            0.1,
            -10.0,
        );
        assert!(qualifies(&e), "{:?}", why_not(&e));
        // Below MIN_GAIN in every channel: noise.
        let n = ev(
            &[
                (Channel::Fx, 0.03),
                (Channel::Fy, 0.04),
                (Channel::Mz, 0.02),
            ],
            0.03,
            -1.0,
        );
        assert!(!qualifies(&n));
    }
}
