//! The parts of the hybrid heuristic of a state ([`HeuristicParts`]) and how the
//! heuristic, the probe's guidance and its greedy list combine them.

use crate::search::Cost;

/// The parts of the hybrid heuristic of a state (`HybridGraph::heuristic_parts`):
/// `h = max(driving, to_go) + steps + behind − ahead`, clamped at zero, or infinite
/// when `reachable` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeuristicParts {
    /// Infinite when the base cell cannot reach the goal at all (`reachability`).
    pub reachable: Cost,
    /// Euclidean distance plus turn (`driving`).
    pub driving: Cost,
    /// The base-cell cost-to-go (`cost_to_go`).
    pub to_go: Cost,
    /// The step bound Σ_k S_k (`heuristic`).
    pub steps: Cost,
    /// Φ's part for feet behind neutral, c · Σ o⁻.
    pub behind: Cost,
    /// Φ's part for feet ahead of neutral, c · Σ o⁺ (subtracted).
    pub ahead: Cost,
    /// The greedy list's share for feet behind neutral, [`GREEDY_OFFSET_PER_M`] · Σ o⁻.
    pub greedy_behind: Cost,
    /// The greedy list's share for feet ahead of neutral, [`GREEDY_OFFSET_PER_M`] · Σ o⁺
    /// (subtracted).
    pub greedy_ahead: Cost,
    /// The feet's mean way to the goal over terrain they could climb, one per metre like
    /// the straight line, plus the same turn as `driving` (`way`; zero where unknown): the
    /// greedy list takes the larger of the two.
    pub way: Cost,
}

/// The weight of each foot's offset from neutral, per metre, in the estimate that orders
/// the probe's greedy list ([`HeuristicParts::greedy_guidance`]): a quarter of what the
/// guidance counts per metre the base still has to go (the driving heuristic's straight
/// line, 1 per metre), so that a base shift toward the goal, which brings the base `l`
/// nearer and leaves all four feet `l` further behind, leaves the estimate where it was.
/// At the heuristic's own weight c (eq. 6's `f · k11 · C_F,min`, 1.34 per metre with the
/// paper's constants) every such shift raises it by `(4c − 1) · l`, a hill a greedy
/// search crosses only after every state below it: before a 0.3 m drop, whose steps
/// need the base shifted over the edge, the whole platform at every heading. The
/// weighted guided list keeps c: there the strong pull of feet toward neutral and ahead
/// of it orders the many footprints of one stance, and a probe ordered by the level
/// estimate alone lost a 0.174 m descent it found in 4,091 expansions (`README.md`,
/// "Planner speed"). Where the feet's way is longer than the straight line (`way`), the
/// shift is not level: it leaves the feet, and their way, where they were and raises the
/// offsets' share by `l`. The way is longer beside a climb, and, by up to 8 % (the octile
/// way's excess), at bearings off the grid's axes and diagonals; the drops measured
/// (`scenarios/step_down.toml`, `step_down_030002`) took 5 % and 4 % fewer expansions
/// with it, not more.
pub const GREEDY_OFFSET_PER_M: f64 = 0.25;

impl HeuristicParts {
    /// `h = max(driving, to_go) + steps + behind − ahead`, clamped at zero; infinite
    /// when `reachable` is.
    pub fn total(&self) -> Cost {
        if self.reachable.is_infinite() {
            return Cost::INFINITY;
        }
        let h = self.driving.max(self.to_go).saturating_add(self.steps).saturating_add(self.behind);
        if h.is_infinite() {
            return h;
        }
        // Clamped at zero (feet ahead of neutral have paid in advance).
        h.saturating_sub(self.ahead)
    }

    /// The guided probe's estimate (`SearchGraph::heuristic_and_guidance`):
    /// [`Self::total`] without the cost-to-go, `driving + steps + behind − ahead`. The
    /// cost-to-go relaxes base shifts over any edge, so it pulls the search to where the
    /// base could be shifted onto a platform most cheaply if steps were free, such as the
    /// open side of a flight of stairs, where the feet cannot follow; the step bound
    /// alone, with the straight-line distance, leads to the front of the flight.
    pub fn guidance(&self) -> Cost {
        let without = Self { to_go: Cost::ZERO, ..*self };
        without.total()
    }

    /// The estimate of the probe's greedy list (`SearchGraph::heuristic_and_guidances`):
    /// [`Self::guidance`] with the feet's offsets weighed at [`GREEDY_OFFSET_PER_M`] and
    /// the straight line replaced by the feet's way where that is longer,
    /// `max(driving, way) + steps + greedy_behind − greedy_ahead`. The straight line
    /// misleads where the goal lies beyond a climb: beside a flight's top the floor is
    /// nearer the goal than the flight's foot, and a probe stuck at the foot searched that
    /// floor at every heading first. The feet's way (`way` module) goes back to the foot
    /// and up the flight. Not a bound, nor meant to be one (the way is counted per cell,
    /// and not every manoeuvre that shortens it pays one per metre): ε′ comes from
    /// [`Self::total`].
    pub fn greedy_guidance(&self) -> Cost {
        let without = Self {
            to_go: Cost::ZERO,
            driving: self.driving.max(self.way),
            behind: self.greedy_behind,
            ahead: self.greedy_ahead,
            ..*self
        };
        without.total()
    }
}
