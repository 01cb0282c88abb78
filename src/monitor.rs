//! The stability monitor: each control step it takes the robot's CoM as MuJoCo computes it
//! and the wheels MuJoCo reports at the terrain, and tells apart three things that an
//! earlier monitor lumped together as "tip-over":
//!
//! - a **static-stability violation**: the CoM's ground projection lies outside the
//!   support polygon of the *supporting* wheels (see `stability`). Its total duration and
//!   worst margin are kept; a scenario bounds the duration
//!   (`expect.max_static_violation_s`).
//! - a **tip-over**: the robot really falls: the base tilts past
//!   [`MonitorLimits::max_tilt_rad`], the trunk (the `base` body: lower body, torso, head)
//!   touches the terrain, or the base drops faster than [`MonitorLimits::fall_speed_m_s`].
//!   Only this sets `tipped`.
//! - **contact events**: fewer wheels supporting than expected, and robot links other
//!   than wheels touching terrain (a shin brushing a stair nosing is a collision, not a
//!   fall).
//!
//! **Supporting wheels.** A wheel supports the robot when MuJoCo lists a contact of it
//! with the terrain within [`MonitorLimits::support_gap_m`] (with the model's contact
//! margin of 0 MuJoCo lists contacts only once a wheel touches; a model with a margin
//! would list them that far out), or when it touched the terrain (within 1 mm) during the
//! last [`MonitorLimits::support_memory_s`] (a wheel bouncing off a bump edge for a few
//! milliseconds still holds the robot up: static stability is about where the robot can
//! rest, and it rests on that wheel again before it can rotate measurably). Its support
//! point is where it last touched.

use crate::sim::Simulation;
pub use crate::support::MonitorLimits;
use crate::support::{convex_hull, stability_margin};
use serde::Serialize;

/// One measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilitySample {
    /// Simulated time, s.
    pub time: f64,
    /// Whole-robot CoM, m.
    pub com: [f64; 3],
    /// Horizontal positions of the supporting wheels.
    pub contacts: Vec<[f64; 2]>,
    /// Support polygon (convex hull of the contacts), counter-clockwise.
    pub support_polygon: Vec<[f64; 2]>,
    /// Signed margin of the CoM projection, m (positive = stable).
    pub margin: f64,
    /// Base roll and pitch, rad.
    pub roll_pitch: [f64; 2],
    /// Vertical speed of the base, m/s.
    pub vertical_speed: f64,
    /// Robot bodies other than wheels touching terrain.
    pub body_collisions: Vec<String>,
}

impl StabilitySample {
    /// Largest of |roll| and |pitch|, rad.
    pub fn tilt(&self) -> f64 {
        self.roll_pitch[0].abs().max(self.roll_pitch[1].abs())
    }
}

/// Why the monitor judged a tip-over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TipCause {
    /// Roll or pitch past the limit.
    Tilt,
    /// The trunk touched the terrain.
    TrunkContact,
    /// The base fell.
    Fall,
}

/// Something the monitor flags.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum MonitorEvent {
    /// The robot fell over.
    TipOver {
        /// Simulated time, s.
        time_s: f64,
        /// What showed it.
        cause: TipCause,
        /// Tilt at that time, degrees.
        tilt_deg: f64,
    },
    /// The CoM left the support polygon of the supporting wheels (reported when it
    /// returns, or at the end of the run).
    StaticViolation {
        /// When it started, s.
        start_s: f64,
        /// How long it lasted, s.
        duration_s: f64,
        /// Most negative margin, m.
        worst_margin_m: f64,
    },
    /// A robot body other than a wheel touched terrain.
    BodyCollision {
        /// Simulated time, s.
        time_s: f64,
        /// The body.
        body: String,
    },
    /// Fewer wheels supported the robot than expected.
    ContactLost {
        /// Simulated time, s.
        time_s: f64,
        /// Wheels supporting.
        wheels: usize,
    },
}

/// The body whose contact with terrain is a fall (the MJCF's root body: lower body,
/// torso, head).
pub const TRUNK_BODY: &str = "base";

/// A static-stability violation under way.
#[derive(Debug, Clone, Copy)]
struct OpenViolation {
    start: f64,
    worst: f64,
}

/// Accumulates samples over a run.
#[derive(Debug, Clone)]
pub struct StabilityMonitor {
    limits: MonitorLimits,
    /// Smallest margin the robot held for at least [`MonitorLimits::margin_hold_s`], m:
    /// the smallest over time of the largest margin within the last `margin_hold_s` (a
    /// dip shorter than that, a wheel bouncing off a bump edge, does not count fully;
    /// the dips below zero are the static violations, timed).
    pub min_margin: f64,
    /// Smallest margin of any single sample, m.
    pub min_instant_margin: f64,
    /// Fewest supporting wheels seen.
    pub min_wheels: usize,
    /// Largest |roll| or |pitch| seen, rad.
    pub max_tilt: f64,
    /// Total time the CoM was outside the support, s.
    pub static_violation_s: f64,
    /// Most negative margin of any violation, m (0 if none).
    pub worst_violation_m: f64,
    /// Events, in time order; each kind is reported again only after it cleared.
    pub events: Vec<MonitorEvent>,
    /// Per wheel (leg-major): last time it touched and where.
    last_touch: [Option<(f64, [f64; 2])>; 8],
    last_time: Option<f64>,
    /// When the base began sinking faster than the fall speed (None: it is not).
    sinking_since: Option<f64>,
    /// Recent (time, margin) samples, margins decreasing: the sliding window maximum.
    window: std::collections::VecDeque<(f64, f64)>,
    violation: Option<OpenViolation>,
    tipped: bool,
    contact_lost: bool,
    colliding: Vec<String>,
}

impl StabilityMonitor {
    /// A monitor with the given limits.
    pub fn new(limits: MonitorLimits) -> Self {
        Self {
            limits,
            min_margin: f64::INFINITY,
            min_instant_margin: f64::INFINITY,
            window: std::collections::VecDeque::new(),
            min_wheels: usize::MAX,
            max_tilt: 0.0,
            static_violation_s: 0.0,
            worst_violation_m: 0.0,
            events: Vec::new(),
            last_touch: [None; 8],
            last_time: None,
            sinking_since: None,
            violation: None,
            tipped: false,
            contact_lost: false,
            colliding: Vec::new(),
        }
    }

    /// Measures the simulation's current state, updates the wheel memory and, after
    /// settling, records the sample.
    pub fn observe(&mut self, sim: &Simulation) -> StabilitySample {
        let base = sim.base();
        let wheels: Vec<WheelReading> = sim
            .wheel_contacts()
            .iter()
            .map(|c| WheelReading {
                index: c.leg.index() * 2 + c.wheel,
                position: [c.position[0], c.position[1]],
                distance: c.distance,
            })
            .collect();
        let s = self.sample(
            sim.time(),
            sim.center_of_mass(),
            &wheels,
            [base.rpy[0], base.rpy[1]],
            base.linear_velocity[2],
            sim.body_terrain_collisions(),
        );
        if s.time >= self.limits.settle_s {
            self.record(&s);
        }
        s
    }

    /// The sample for wheel readings `wheels` at `time`, updating the wheel memory.
    fn sample(
        &mut self,
        time: f64,
        com: [f64; 3],
        wheels: &[WheelReading],
        roll_pitch: [f64; 2],
        vertical_speed: f64,
        body_collisions: Vec<String>,
    ) -> StabilitySample {
        let mut near = [None; 8];
        for w in wheels {
            if w.distance <= crate::sim::TOUCHING_M {
                self.last_touch[w.index] = Some((time, w.position));
            }
            if w.distance <= self.limits.support_gap_m {
                near[w.index] = Some(w.position);
            }
        }
        let memory = self.limits.support_memory_s + 1e-9;
        let contacts: Vec<[f64; 2]> = (0..8)
            .filter_map(|k| {
                near[k].or(self.last_touch[k].filter(|(t, _)| time - t <= memory).map(|(_, p)| p))
            })
            .collect();
        StabilitySample {
            time,
            com,
            support_polygon: convex_hull(&contacts),
            margin: stability_margin(&contacts, [com[0], com[1]]),
            contacts,
            roll_pitch,
            vertical_speed,
            body_collisions,
        }
    }

    /// Records a sample: minima, violations and events.
    pub fn record(&mut self, s: &StabilitySample) {
        let dt = self.last_time.map_or(0.0, |t| (s.time - t).max(0.0));
        self.last_time = Some(s.time);
        self.min_instant_margin = self.min_instant_margin.min(s.margin);
        while self.window.back().is_some_and(|&(_, m)| m <= s.margin) {
            self.window.pop_back();
        }
        self.window.push_back((s.time, s.margin));
        while self
            .window
            .front()
            .is_some_and(|&(t, _)| t < s.time - self.limits.margin_hold_s - 1e-9)
        {
            self.window.pop_front();
        }
        if let Some(&(_, held)) = self.window.front() {
            self.min_margin = self.min_margin.min(held);
        }
        self.min_wheels = self.min_wheels.min(s.contacts.len());
        let tilt = s.tilt();
        self.max_tilt = self.max_tilt.max(tilt);

        // Static stability: a violation lasts from the first sample outside to the first
        // sample back inside.
        if self.violation.is_some() {
            self.static_violation_s += dt;
        }
        if s.margin < 0.0 {
            let v = self.violation.get_or_insert(OpenViolation { start: s.time, worst: 0.0 });
            v.worst = v.worst.min(s.margin);
            self.worst_violation_m = self.worst_violation_m.min(s.margin);
        } else {
            self.close_violation(s.time);
        }

        // Tip-over.
        self.sinking_since = if s.vertical_speed < -self.limits.fall_speed_m_s {
            Some(self.sinking_since.unwrap_or(s.time))
        } else {
            None
        };
        let falling =
            self.sinking_since.is_some_and(|t0| s.time - t0 >= self.limits.fall_duration_s - 1e-9);
        let cause = if tilt > self.limits.max_tilt_rad {
            Some(TipCause::Tilt)
        } else if s.body_collisions.iter().any(|b| b == TRUNK_BODY) {
            Some(TipCause::TrunkContact)
        } else if falling {
            Some(TipCause::Fall)
        } else {
            None
        };
        if let Some(cause) = cause
            && !self.tipped
        {
            self.events.push(MonitorEvent::TipOver {
                time_s: s.time,
                cause,
                tilt_deg: tilt.to_degrees(),
            });
        }
        self.tipped = cause.is_some();

        // Contact events.
        let lost = s.contacts.len() < self.limits.expected_wheels;
        if lost && !self.contact_lost {
            self.events
                .push(MonitorEvent::ContactLost { time_s: s.time, wheels: s.contacts.len() });
        }
        self.contact_lost = lost;
        for body in &s.body_collisions {
            if !self.colliding.contains(body) {
                self.events
                    .push(MonitorEvent::BodyCollision { time_s: s.time, body: body.clone() });
            }
        }
        self.colliding.clone_from(&s.body_collisions);
    }

    fn close_violation(&mut self, now: f64) {
        if let Some(v) = self.violation.take() {
            self.events.push(MonitorEvent::StaticViolation {
                start_s: v.start,
                duration_s: now - v.start,
                worst_margin_m: v.worst,
            });
        }
    }

    /// Ends the run: a violation still under way is reported.
    pub fn finish(&mut self) {
        if let Some(t) = self.last_time {
            self.close_violation(t);
        }
    }

    /// Whether the robot fell over.
    pub fn tipped(&self) -> bool {
        self.events.iter().any(|e| matches!(e, MonitorEvent::TipOver { .. }))
    }

    /// Bodies that touched terrain, sorted, each once.
    pub fn collided_bodies(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .events
            .iter()
            .filter_map(|e| match e {
                MonitorEvent::BodyCollision { body, .. } => Some(body.clone()),
                _ => None,
            })
            .collect();
        v.sort();
        v.dedup();
        v
    }
}

/// One wheel as the simulation reports it.
#[derive(Debug, Clone, Copy)]
struct WheelReading {
    /// Leg index · 2 + wheel.
    index: usize,
    position: [f64; 2],
    distance: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eight wheels of a 1 m × 0.6 m footprint around the origin, at `distance`.
    fn wheels(distance: f64) -> Vec<WheelReading> {
        let mut v = Vec::new();
        for (leg, (x, y)) in [(0.5, 0.3), (0.5, -0.3), (-0.5, 0.3), (-0.5, -0.3)].iter().enumerate()
        {
            for (w, dy) in [0.06, -0.06].iter().enumerate() {
                v.push(WheelReading { index: leg * 2 + w, position: [*x, y + dy], distance });
            }
        }
        v
    }

    fn level(
        m: &mut StabilityMonitor,
        t: f64,
        com: [f64; 2],
        w: &[WheelReading],
    ) -> StabilitySample {
        let s = m.sample(t, [com[0], com[1], 0.5], w, [0.0, 0.0], 0.0, Vec::new());
        m.record(&s);
        s
    }

    #[test]
    fn a_wheel_hovering_within_the_gap_still_supports() {
        // All wheels 3 mm up (inside MuJoCo's 4 mm gap, outside "touching"): a full
        // footprint; the outer wheels stand at |y| = 0.36 and |x| = 0.5, so the margin of
        // the centre is 0.36.
        let mut m = StabilityMonitor::new(MonitorLimits::default());
        let s = level(&mut m, 0.0, [0.0, 0.0], &wheels(0.003));
        assert_eq!(s.contacts.len(), 8);
        assert!((s.margin - 0.36).abs() < 1e-12, "{}", s.margin);
        // 6 mm up and never touched: not supporting.
        let mut m = StabilityMonitor::new(MonitorLimits::default());
        let s = level(&mut m, 0.0, [0.0, 0.0], &wheels(0.006));
        assert!(s.contacts.is_empty() && s.margin == f64::NEG_INFINITY);
    }

    #[test]
    fn a_bounce_shorter_than_the_memory_is_no_violation() {
        let mut m = StabilityMonitor::new(MonitorLimits::default());
        level(&mut m, 0.00, [0.0, 0.0], &wheels(0.0));
        // The whole robot in the air for 20 ms (two ticks), then down again.
        for t in [0.01, 0.02] {
            let s = level(&mut m, t, [0.0, 0.0], &[]);
            assert_eq!(s.contacts.len(), 8, "remembered at {t}");
        }
        level(&mut m, 0.03, [0.0, 0.0], &wheels(0.0));
        assert_eq!(m.static_violation_s, 0.0);
        assert!(!m.tipped());
        // Airborne for longer than the memory: the support is gone.
        let s = level(&mut m, 0.07, [0.0, 0.0], &[]);
        assert!(s.contacts.is_empty());
    }

    #[test]
    fn a_violation_is_timed_and_its_worst_margin_kept_but_is_no_tip_over() {
        let mut m = StabilityMonitor::new(MonitorLimits::default());
        // The four left wheels only: their hull spans y ∈ [0.24, 0.36]; the CoM at
        // y = 0.14 is 0.10 m outside.
        let left: Vec<WheelReading> =
            wheels(0.0).into_iter().filter(|w| [0, 1, 4, 5].contains(&w.index)).collect();
        level(&mut m, 0.0, [0.0, 0.0], &wheels(0.0));
        for k in 1..=10 {
            level(&mut m, 0.1 + 0.01 * f64::from(k), [0.0, 0.14], &left);
        }
        level(&mut m, 0.3, [0.0, 0.0], &wheels(0.0));
        m.finish();
        // Memory keeps the right wheels until 0.03 s after their last touch (0.0 s), so
        // from the first sample at 0.11 s the support is the left wheels.
        let v: Vec<_> = m
            .events
            .iter()
            .filter_map(|e| match e {
                MonitorEvent::StaticViolation { start_s, duration_s, worst_margin_m } => {
                    Some((*start_s, *duration_s, *worst_margin_m))
                }
                _ => None,
            })
            .collect();
        assert_eq!(v.len(), 1, "{:?}", m.events);
        assert!((v[0].0 - 0.11).abs() < 1e-9 && (v[0].1 - 0.19).abs() < 1e-9, "{v:?}");
        assert!((v[0].2 + 0.10).abs() < 1e-9, "{v:?}");
        // The total is the events' durations.
        assert!((m.static_violation_s - 0.19).abs() < 1e-9, "{}", m.static_violation_s);
        assert!((m.worst_violation_m + 0.10).abs() < 1e-9);
        assert!(!m.tipped(), "level robot: a violation, not a fall");
    }

    #[test]
    fn the_run_minimum_is_the_margin_held_for_the_hold_time() {
        let mut m = StabilityMonitor::new(MonitorLimits::default());
        let left: Vec<WheelReading> =
            wheels(0.0).into_iter().filter(|w| [0, 1, 4, 5].contains(&w.index)).collect();
        // 0.36 m for a while; then the CoM 0.14 m to the left (0.22 m inside all eight
        // wheels) while the right wheels are off for 60 ms: the margin drops to −0.10
        // once the 30 ms memory has passed, for 30 ms, then they are back. The held
        // minimum is 0.22; the instant one −0.10.
        for k in 0..10 {
            level(&mut m, 0.01 * f64::from(k), [0.0, 0.0], &wheels(0.0));
        }
        for k in 10..16 {
            level(&mut m, 0.01 * f64::from(k), [0.0, 0.14], &left);
        }
        for k in 16..30 {
            level(&mut m, 0.01 * f64::from(k), [0.0, 0.0], &wheels(0.0));
        }
        assert!((m.min_instant_margin + 0.10).abs() < 1e-9, "{}", m.min_instant_margin);
        assert!((m.min_margin - 0.22).abs() < 1e-9, "{}", m.min_margin);
        // Held for longer than 50 ms: it counts.
        for k in 30..40 {
            level(&mut m, 0.01 * f64::from(k), [0.0, 0.14], &left);
        }
        assert!((m.min_margin + 0.10).abs() < 1e-9, "{}", m.min_margin);
    }

    #[test]
    fn tilt_trunk_contact_and_a_fall_are_tip_overs() {
        // Each condition held for 0.2 s.
        let tip = |roll: f64, vz: f64, bodies: Vec<String>| {
            let mut m = StabilityMonitor::new(MonitorLimits::default());
            for k in 0..=20 {
                let t = 0.01 * f64::from(k);
                let s = m.sample(t, [0.0, 0.0, 0.5], &wheels(0.0), [roll, 0.0], vz, bodies.clone());
                m.record(&s);
            }
            m.events.iter().find_map(|e| match e {
                MonitorEvent::TipOver { cause, .. } => Some(*cause),
                _ => None,
            })
        };
        assert_eq!(tip(0.0, 0.0, vec![]), None);
        assert_eq!(tip(40f64.to_radians(), 0.0, vec![]), Some(TipCause::Tilt));
        assert_eq!(tip(0.0, 0.0, vec!["base".into()]), Some(TipCause::TrunkContact));
        assert_eq!(tip(0.0, -1.0, vec![]), Some(TipCause::Fall));
        // A shin on a stair nosing is a collision event, not a fall.
        assert_eq!(tip(0.0, 0.0, vec!["fl_shin".into()]), None);
        // A wheel rolling off a bump: 0.08 s of fast sinking is no fall.
        let mut m = StabilityMonitor::new(MonitorLimits::default());
        for k in 0..=30 {
            let t = 0.01 * f64::from(k);
            let vz = if (0.1..0.18).contains(&t) { -0.6 } else { 0.0 };
            let s = m.sample(t, [0.0, 0.0, 0.5], &wheels(0.0), [0.0, 0.0], vz, Vec::new());
            m.record(&s);
        }
        assert!(!m.tipped(), "{:?}", m.events);
    }
}
