//! Contact confirmation for a placed foot (issue 7): the planned foothold is reached, but
//! weight goes back onto the foot only once MuJoCo reports one of its wheels touching the
//! terrain. Until then the foot keeps being lowered, at a bounded speed and by a bounded
//! extra distance; if no contact comes, the step fails.
//!
//! A pure state machine: the caller feeds it the measured contact each control tick and
//! applies the returned extra lowering to the foot's target.

/// Tuning of the confirmation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactConfirmConfig {
    /// Speed of the extra lowering, m/s.
    pub lower_speed_mps: f64,
    /// Largest extra lowering below the planned foothold, m.
    pub max_extra_m: f64,
    /// Contact must be seen for this long without a break to count, s.
    pub confirm_s: f64,
    /// Time waited at the largest extra lowering before failing, s.
    pub wait_at_bottom_s: f64,
}

impl Default for ContactConfirmConfig {
    fn default() -> Self {
        Self { lower_speed_mps: 0.04, max_extra_m: 0.05, confirm_s: 0.1, wait_at_bottom_s: 0.5 }
    }
}

/// What the confirmation says after a tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactStatus {
    /// Still lowering or waiting for a steady contact; the foot target goes `extra_m`
    /// below the planned foothold.
    Pending {
        /// Extra lowering so far, m (≥ 0).
        extra_m: f64,
    },
    /// The foot touches the terrain: weight may go onto it; the foot stays `extra_m` below
    /// the planned foothold.
    Confirmed {
        /// Extra lowering that was needed, m.
        extra_m: f64,
    },
    /// No contact even `max_extra_m` below the foothold.
    Failed {
        /// Extra lowering tried, m.
        extra_m: f64,
    },
}

/// The confirmation of one foot placement.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactConfirm {
    config: ContactConfirmConfig,
    extra_m: f64,
    in_contact_s: f64,
    at_bottom_s: f64,
    status: ContactStatus,
}

impl ContactConfirm {
    /// A confirmation that starts at the planned foothold.
    pub fn new(config: ContactConfirmConfig) -> Self {
        Self {
            config,
            extra_m: 0.0,
            in_contact_s: 0.0,
            at_bottom_s: 0.0,
            status: ContactStatus::Pending { extra_m: 0.0 },
        }
    }

    /// The current status.
    pub fn status(&self) -> ContactStatus {
        self.status
    }

    /// One control tick of `dt` s with the measured contact of the foot.
    pub fn update(&mut self, in_contact: bool, dt: f64) -> ContactStatus {
        if !matches!(self.status, ContactStatus::Pending { .. }) {
            return self.status;
        }
        let c = self.config;
        if in_contact {
            self.in_contact_s += dt;
            if self.in_contact_s >= c.confirm_s - 1e-9 {
                self.status = ContactStatus::Confirmed { extra_m: self.extra_m };
                return self.status;
            }
        } else {
            self.in_contact_s = 0.0;
            if self.extra_m >= c.max_extra_m - 1e-12 {
                self.at_bottom_s += dt;
                if self.at_bottom_s >= c.wait_at_bottom_s - 1e-9 {
                    self.status = ContactStatus::Failed { extra_m: self.extra_m };
                    return self.status;
                }
            } else {
                self.extra_m = (self.extra_m + c.lower_speed_mps * dt).min(c.max_extra_m);
            }
        }
        self.status = ContactStatus::Pending { extra_m: self.extra_m };
        self.status
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> ContactConfirmConfig {
        ContactConfirmConfig {
            lower_speed_mps: 0.05,
            max_extra_m: 0.02,
            confirm_s: 0.03,
            wait_at_bottom_s: 0.2,
        }
    }

    #[test]
    fn contact_at_the_foothold_confirms_after_the_confirm_time_without_lowering() {
        let mut c = ContactConfirm::new(cfg());
        // 10 ms ticks: 0.03 s of contact = three ticks.
        assert_eq!(c.update(true, 0.01), ContactStatus::Pending { extra_m: 0.0 });
        assert_eq!(c.update(true, 0.01), ContactStatus::Pending { extra_m: 0.0 });
        assert_eq!(c.update(true, 0.01), ContactStatus::Confirmed { extra_m: 0.0 });
        // Final: later ticks do not change it.
        assert_eq!(c.update(false, 0.01), ContactStatus::Confirmed { extra_m: 0.0 });
    }

    #[test]
    fn missing_contact_lowers_at_the_set_speed_and_a_break_restarts_the_count() {
        let mut c = ContactConfirm::new(cfg());
        // 0.05 m/s · 0.1 s = 5 mm per tick of 0.1 s.
        match c.update(false, 0.1) {
            ContactStatus::Pending { extra_m } => assert!((extra_m - 0.005).abs() < 1e-12),
            s => panic!("{s:?}"),
        }
        // Contact for 0.02 s, then lost: the count restarts.
        c.update(true, 0.02);
        match c.update(false, 0.1) {
            ContactStatus::Pending { extra_m } => assert!((extra_m - 0.010).abs() < 1e-12),
            s => panic!("{s:?}"),
        }
        c.update(true, 0.02);
        match c.update(true, 0.02) {
            ContactStatus::Confirmed { extra_m } => assert!((extra_m - 0.010).abs() < 1e-12),
            s => panic!("{s:?}"),
        }
    }

    #[test]
    fn no_contact_within_the_extra_distance_fails_after_the_wait() {
        let mut c = ContactConfirm::new(cfg());
        // 0.02 m at 0.05 m/s takes 0.4 s (four ticks of 0.1 s), then 0.2 s at the bottom.
        for _ in 0..4 {
            assert!(matches!(c.update(false, 0.1), ContactStatus::Pending { .. }));
        }
        assert_eq!(c.update(false, 0.1), ContactStatus::Pending { extra_m: 0.02 });
        assert_eq!(c.update(false, 0.1), ContactStatus::Failed { extra_m: 0.02 });
    }
}
