//! The stability monitor: each control step it takes the robot's CoM as MuJoCo computes it
//! and the wheels MuJoCo reports in terrain contact, and measures the static stability
//! margin (see `stability`), tilt and body-terrain collisions. It keeps minima and a list of
//! events for the run's summary.

use crate::sim::Simulation;
use crate::stability::{convex_hull, stability_margin};
use serde::Serialize;

/// One measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilitySample {
    /// Simulated time, s.
    pub time: f64,
    /// Whole-robot CoM, m.
    pub com: [f64; 3],
    /// Horizontal positions of the wheels in contact.
    pub contacts: Vec<[f64; 2]>,
    /// Support polygon (convex hull of the contacts), counter-clockwise.
    pub support_polygon: Vec<[f64; 2]>,
    /// Signed margin of the CoM projection, m (positive = stable).
    pub margin: f64,
    /// Base roll and pitch, rad.
    pub roll_pitch: [f64; 2],
    /// Robot bodies other than wheels touching terrain.
    pub body_collisions: Vec<String>,
}

/// Something the monitor flags.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum MonitorEvent {
    /// The CoM left the support polygon or the base tilted past the limit.
    TipOver {
        /// Simulated time, s.
        time_s: f64,
        /// Margin at that time, m.
        margin_m: f64,
    },
    /// A robot body other than a wheel touched terrain.
    BodyCollision {
        /// Simulated time, s.
        time_s: f64,
        /// The body.
        body: String,
    },
    /// Fewer wheels touched the ground than expected.
    ContactLost {
        /// Simulated time, s.
        time_s: f64,
        /// Wheels in contact.
        wheels: usize,
    },
}

/// Limits the monitor checks against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonitorLimits {
    /// Roll or pitch beyond this counts as tipping, rad.
    pub max_tilt_rad: f64,
    /// Wheels expected on the ground (8 while driving).
    pub expected_wheels: usize,
}

impl Default for MonitorLimits {
    fn default() -> Self {
        Self { max_tilt_rad: 35f64.to_radians(), expected_wheels: 8 }
    }
}

/// Accumulates samples over a run.
#[derive(Debug, Clone)]
pub struct StabilityMonitor {
    limits: MonitorLimits,
    /// Smallest margin seen, m.
    pub min_margin: f64,
    /// Fewest wheels in contact seen.
    pub min_wheels: usize,
    /// Largest |roll| or |pitch| seen, rad.
    pub max_tilt: f64,
    /// Events, in time order; each kind is reported again only after it cleared.
    pub events: Vec<MonitorEvent>,
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
            min_wheels: usize::MAX,
            max_tilt: 0.0,
            events: Vec::new(),
            tipped: false,
            contact_lost: false,
            colliding: Vec::new(),
        }
    }

    /// Measures the simulation's current state without recording it.
    pub fn measure(sim: &Simulation) -> StabilitySample {
        let com = sim.center_of_mass();
        let contacts: Vec<[f64; 2]> =
            sim.wheel_contacts().iter().map(|c| [c.position[0], c.position[1]]).collect();
        let rpy = sim.base().rpy;
        StabilitySample {
            time: sim.time(),
            com,
            support_polygon: convex_hull(&contacts),
            margin: stability_margin(&contacts, [com[0], com[1]]),
            contacts,
            roll_pitch: [rpy[0], rpy[1]],
            body_collisions: sim.body_terrain_collisions(),
        }
    }

    /// Measures and records the current state.
    pub fn observe(&mut self, sim: &Simulation) -> StabilitySample {
        let s = Self::measure(sim);
        self.record(&s);
        s
    }

    /// Records a sample: minima and events.
    pub fn record(&mut self, s: &StabilitySample) {
        self.min_margin = self.min_margin.min(s.margin);
        self.min_wheels = self.min_wheels.min(s.contacts.len());
        let tilt = s.roll_pitch[0].abs().max(s.roll_pitch[1].abs());
        self.max_tilt = self.max_tilt.max(tilt);
        let tipping = s.margin < 0.0 || tilt > self.limits.max_tilt_rad;
        if tipping && !self.tipped {
            self.events.push(MonitorEvent::TipOver { time_s: s.time, margin_m: s.margin });
        }
        self.tipped = tipping;
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

    /// Whether a tip-over was seen.
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
