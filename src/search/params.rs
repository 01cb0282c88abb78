//! Search parameters ([`SearchParams`]) and the ε schedule of ARA*.
//!
//! ε (the heuristic weight) is held in fixed point, [`EPS_SCALE`] = 1000 per unit, so the
//! weighted key `g·1000 + ε_milli·h` is an exact integer and every ε the schedule
//! produces is reproducible. A* ignores the ε fields.

use std::time::Duration;

/// Fixed-point scale of ε: `ε = eps_milli / EPS_SCALE` (resolution 0.001).
pub const EPS_SCALE: u64 = 1000;

/// Parameters of a search. `Default` gives the paper's ARA* set-up (ε from 3.0 decaying
/// exponentially to 1.0, Klamt & Behnke 2017, Sec. VII-B) with no limits.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchParams {
    /// ARA*: ε of the first search of the schedule (≥ 1; rounded to 0.001). Paper: 3.0.
    pub initial_epsilon: f64,
    /// ARA*: ε of a greedy search run before the schedule (≥ `initial_epsilon`; equal:
    /// none), or `None` for the paper's schedule alone. Its solution is published with
    /// its bound ε′ and kept as the answer should a limit stop the schedule, which then
    /// starts from scratch (`arastar`). Not in the paper.
    pub probe_epsilon: Option<f64>,
    /// ARA*: whether the probe is guided: every other expansion taken from a second OPEN
    /// list ordered by the graph's guidance (`SearchGraph::heuristic_and_guidance`,
    /// `arastar` module docs). Not in the paper; the bound it certifies is unchanged.
    pub probe_guidance: bool,
    /// ARA*: the expansions after which a guided probe that has not reached a goal adds
    /// its greedy list (`engine` module docs, "Guided search"), or `None` for never. Its
    /// path then carries its certified ε′ alone.
    pub probe_greedy_after: Option<u64>,
    /// ARA*: ε of the last search (≥ 1, ≤ `initial_epsilon`). 1.0 proves optimality.
    pub final_epsilon: f64,
    /// ARA*: after each solution, `ε − final_epsilon` is multiplied by this factor
    /// (exponential decay, in `(0, 1)`). 0.5 gives 3, 2, 1.5, 1.25, … 1.
    pub epsilon_decay: f64,
    /// ARA*: once `ε − final_epsilon` would fall below this, ε jumps to `final_epsilon`
    /// (otherwise an exponential decay never arrives). ≥ 0.
    pub epsilon_snap: f64,
    /// Wall-clock budget for the whole search (all ARA* iterations). Checked every few
    /// expansions and between iterations; the best solution found so far is returned.
    pub time_limit: Option<Duration>,
    /// Cap on expansions, counted over all iterations.
    pub max_expansions: Option<u64>,
    /// ARA*: once the probe has found a path, the expansions the schedule may spend
    /// after it (a cap that leaves the probe's path as the answer on any machine, where a
    /// time limit stops wherever the CPU happens to be). Without a probe's path, no cap:
    /// a search that would prove "no path" is not cut short.
    pub schedule_max_expansions: Option<u64>,
    /// Cap on generated states (memory guard for huge graphs). The index type caps it
    /// at `u32::MAX − 1` in any case.
    pub max_states: Option<usize>,
}

/// Expansions of a guided probe before its greedy list joins (`probe_greedy_after`). A
/// probe that has found no path by then is crossing a plateau its weighted lists flood
/// (on 30 generated flights the weighted probe's 20 paths that came sooner took a median
/// of 1.8 k expansions; the 7 that came later, 27–282 k, and 3 flights had none within
/// 20 s); below it the probe's path is the weighted search's, whose ε holds.
pub const PROBE_GREEDY_AFTER: u64 = 20_000;

impl Default for SearchParams {
    fn default() -> Self {
        Self {
            initial_epsilon: 3.0,
            probe_epsilon: None,
            probe_guidance: true,
            probe_greedy_after: Some(PROBE_GREEDY_AFTER),
            final_epsilon: 1.0,
            epsilon_decay: 0.5,
            epsilon_snap: 0.01,
            time_limit: None,
            max_expansions: None,
            schedule_max_expansions: None,
            max_states: None,
        }
    }
}

/// Invalid [`SearchParams`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamsError {
    /// An ε below 1, or not finite.
    #[error("{name} = {value} must be finite and at least 1")]
    Epsilon {
        /// Field name.
        name: &'static str,
        /// Offending value.
        value: f64,
    },
    /// `probe_epsilon < initial_epsilon`.
    #[error("probe_epsilon = {probe} is below initial_epsilon = {initial}")]
    ProbeOrder {
        /// `probe_epsilon`.
        probe: f64,
        /// `initial_epsilon`.
        initial: f64,
    },
    /// `initial_epsilon < final_epsilon`.
    #[error("initial_epsilon = {initial} is below final_epsilon = {final_epsilon}")]
    EpsilonOrder {
        /// `initial_epsilon`.
        initial: f64,
        /// `final_epsilon`.
        final_epsilon: f64,
    },
    /// `epsilon_decay` outside `(0, 1)`.
    #[error("epsilon_decay = {0} must lie in (0, 1)")]
    Decay(f64),
    /// `epsilon_snap` negative or not finite.
    #[error("epsilon_snap = {0} must be finite and non-negative")]
    Snap(f64),
}

/// The validated ε schedule in fixed point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct EpsilonSchedule {
    /// ε of the probe, when there is one above `initial`.
    pub probe: Option<u64>,
    pub initial: u64,
    pub final_: u64,
    decay: u64, // per mille of the gap kept, 1..=999
    snap: u64,
}

fn to_milli(name: &'static str, value: f64) -> Result<u64, ParamsError> {
    if !(1.0..=1e9).contains(&value) {
        return Err(ParamsError::Epsilon { name, value });
    }
    Ok((value * EPS_SCALE as f64).round() as u64)
}

impl SearchParams {
    /// Checks the ε fields.
    ///
    /// # Errors
    /// The first invalid field.
    pub fn validate(&self) -> Result<(), ParamsError> {
        self.schedule().map(|_| ())
    }

    pub(crate) fn schedule(&self) -> Result<EpsilonSchedule, ParamsError> {
        let initial = to_milli("initial_epsilon", self.initial_epsilon)?;
        let final_ = to_milli("final_epsilon", self.final_epsilon)?;
        let probe = match self.probe_epsilon {
            Some(p) => {
                let probe = to_milli("probe_epsilon", p)?;
                if probe < initial {
                    return Err(ParamsError::ProbeOrder {
                        probe: p,
                        initial: self.initial_epsilon,
                    });
                }
                (probe > initial).then_some(probe)
            }
            None => None,
        };
        if initial < final_ {
            return Err(ParamsError::EpsilonOrder {
                initial: self.initial_epsilon,
                final_epsilon: self.final_epsilon,
            });
        }
        if !(self.epsilon_decay > 0.0 && self.epsilon_decay < 1.0) {
            return Err(ParamsError::Decay(self.epsilon_decay));
        }
        if !(self.epsilon_snap.is_finite() && self.epsilon_snap >= 0.0) {
            return Err(ParamsError::Snap(self.epsilon_snap));
        }
        let decay = ((self.epsilon_decay * EPS_SCALE as f64).round() as u64).clamp(1, 999);
        let snap = (self.epsilon_snap.min(1e9) * EPS_SCALE as f64).round() as u64;
        Ok(EpsilonSchedule { probe, initial, final_, decay, snap })
    }
}

impl EpsilonSchedule {
    /// ε of the first search: the probe's, or the schedule's first.
    pub fn first(&self) -> u64 {
        self.probe.unwrap_or(self.initial)
    }

    /// The ε after `eps` (both in milli): `final + (eps − final)·decay`, rounded, strictly
    /// smaller than `eps`, snapped to `final` once the gap is below `snap`.
    pub fn next(&self, eps: u64) -> u64 {
        let gap = eps.saturating_sub(self.final_);
        if gap == 0 {
            return self.final_;
        }
        let new_gap = (gap * self.decay + EPS_SCALE / 2) / EPS_SCALE;
        let new_gap = new_gap.min(gap - 1);
        if new_gap < self.snap.max(1) { self.final_ } else { self.final_ + new_gap }
    }
}

/// ε in milli-units as an `f64`.
pub(crate) fn eps_to_f64(eps_milli: u64) -> f64 {
    eps_milli as f64 / EPS_SCALE as f64
}

/// Which search to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Algorithm {
    /// Optimal A*.
    AStar,
    /// Anytime ARA* with the ε schedule of the search parameters.
    AraStar,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_schedule_decays_to_one() {
        let s = SearchParams::default().schedule().expect("valid defaults");
        let mut eps = s.initial;
        let mut seen = vec![eps];
        while eps > s.final_ {
            eps = s.next(eps);
            seen.push(eps);
        }
        assert_eq!(seen, vec![3000, 2000, 1500, 1250, 1125, 1063, 1032, 1016, 1000]);
    }

    #[test]
    fn schedule_strictly_decreases_even_with_slow_decay() {
        let p = SearchParams {
            initial_epsilon: 1.005,
            epsilon_decay: 0.999,
            epsilon_snap: 0.0,
            ..SearchParams::default()
        };
        let s = p.schedule().expect("valid");
        let mut eps = s.initial;
        let mut n = 0;
        while eps > s.final_ {
            let next = s.next(eps);
            assert!(next < eps);
            eps = next;
            n += 1;
        }
        assert_eq!(n, 5);
    }

    #[test]
    fn invalid_params_are_rejected() {
        let bad = |p: SearchParams| p.validate().is_err();
        let d = SearchParams::default;
        assert!(bad(SearchParams { initial_epsilon: 0.5, ..d() }));
        assert!(bad(SearchParams { final_epsilon: f64::NAN, ..d() }));
        assert!(bad(SearchParams { initial_epsilon: 1.0, final_epsilon: 2.0, ..d() }));
        assert!(bad(SearchParams { epsilon_decay: 1.0, ..d() }));
        assert!(bad(SearchParams { epsilon_decay: 0.0, ..d() }));
        assert!(bad(SearchParams { epsilon_snap: -1.0, ..d() }));
        assert!(d().validate().is_ok());
    }
}
