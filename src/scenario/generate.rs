//! Seeded random scenarios, the pure half of `momaro generate`: eight classes of course,
//! each drawn from a seed into scenario TOML text.
//!
//! A case is a class and a seed; its text is a function of those two and of how many
//! draws of the seed's stream were rejected before it, nothing else (the crate's own
//! generator [`crate::rng::Rng`], no clock, no hash-map order), so a case is reproducible
//! from its seed alone. Every draw is checked here to parse as a [`Scenario`] and to keep
//! its map within [`MAX_MAP_M`]; whether the robot can stand at its start and goal needs
//! the robot, so `jobs::generate` checks that (`jobs::plan::prepare`) and asks for the
//! next draw of the same stream ([`Draws::next_case`]) when it fails.
//!
//! Courses are laid out in a local *course frame* (the robot travels along +x, y left)
//! and turned into the world: by a quarter turn for the classes whose obstacles must cut
//! the whole map (no detour), by any yaw for stairs. Obstacles meant to block (a platform
//! edge, a block across the path, a wall with a doorway) reach 1 m beyond the map on
//! every side, so no way around them exists in the simulated world either.
//!
//! The parameter ranges and where they come from are documented in the "Generated
//! scenarios" section of `scenarios/README.md`; the constants below are the single
//! source of the numbers.

use super::terrain::Primitive;
use super::{MapExtent, Outcome, PoseSpec, Scenario, ScenarioError};
use crate::params::{FootModel, StepModel};
use crate::rng::Rng;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// A class of generated course.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// A flight of stairs, climbed or descended.
    Stairs,
    /// Start on a platform, get down its edge.
    StepDown,
    /// A block across the path: step up, drive across, step down.
    UpAndOver,
    /// Random boxes and poles with low bumps, a way left free.
    Clutter,
    /// A wall across the map with a doorway, sometimes a corridor.
    Narrow,
    /// Flat ground, start and goal headings off the planner's lattice.
    Headings,
    /// Clutter, a climb (block or stairs) and a step down on one course.
    Mixed,
    /// No way exists: the planner must answer "no path".
    Impossible,
}

impl Class {
    /// Every class, in the order `momaro generate` cycles through them.
    pub const ALL: [Class; 8] = [
        Class::Stairs,
        Class::StepDown,
        Class::UpAndOver,
        Class::Clutter,
        Class::Narrow,
        Class::Headings,
        Class::Mixed,
        Class::Impossible,
    ];

    /// The names of [`Class::ALL`], as written in files and on the command line.
    pub const NAMES: [&'static str; 8] = [
        "stairs",
        "step_down",
        "up_and_over",
        "clutter",
        "narrow",
        "headings",
        "mixed",
        "impossible",
    ];

    /// The class's name (`step_down`, ...).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The class named `name`, if any.
    pub fn from_name(name: &str) -> Option<Class> {
        Self::NAMES.iter().position(|&n| n == name).map(|k| Self::ALL[k])
    }

    /// The class of case `i` of a run without `--class`: `i mod 8` in [`Class::ALL`]'s order.
    pub fn of_case(i: u64) -> Class {
        Self::ALL[(i % Self::ALL.len() as u64) as usize]
    }

    /// The step and foot models the class's files name in `[params]`, if any: stairs
    /// (treads of 0.25–0.40 m, shorter than the robot's 0.7 m hip spacing) need the
    /// stairs step model, and the wheel pairs' footprint keeps more of a tread than the
    /// paper's disc (README, "Step model" and "Foot model"), as the repository's own
    /// stairs scenarios do. The other classes name none and get the scenario's defaults
    /// for their terrain (`scenario::default_models`): mixed courses whose climb is 2–3
    /// steps get the wheel pair, the rest the paper's models.
    pub fn models(self) -> Option<(StepModel, FootModel)> {
        match self {
            Class::Stairs => Some((StepModel::Stairs, FootModel::WheelPair)),
            _ => None,
        }
    }
}

impl std::fmt::Display for Class {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Class {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Class::from_name(s)
            .ok_or_else(|| format!("unknown class `{s}` (one of {})", Class::NAMES.join(", ")))
    }
}

/// A closed interval a drawn parameter lies in.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Span {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Span {
    const fn new(lo: f64, hi: f64) -> Self {
        Self { lo, hi }
    }

    /// Whether `v` lies in the interval (1 µ of slack for the rounding of written values).
    pub fn contains(&self, v: f64) -> bool {
        v >= self.lo - 1e-6 && v <= self.hi + 1e-6
    }

    /// A uniform draw rounded to `decimals`, clamped into the interval.
    fn draw(&self, rng: &mut Rng, decimals: i32) -> f64 {
        round_to(rng.range(self.lo, self.hi), decimals).clamp(self.lo, self.hi)
    }
}

/// Number of steps of a generated flight of stairs.
pub const STAIR_STEPS: [u32; 2] = [2, 8];
/// Riser height of generated stairs, m (IBC/IRC risers, plus steep old stairs).
pub const STAIR_RISE_M: Span = Span::new(0.10, 0.22);
/// Tread depth of generated stairs, m (IRC's 0.254 m minimum rounded down to 0.25).
pub const STAIR_TREAD_M: Span = Span::new(0.25, 0.40);
/// Clear width of generated stairs (between the walls, if any), m.
pub const STAIR_WIDTH_M: Span = Span::new(1.1, 2.0);
/// Depth of the top landing, where the robot stands at the top, m.
pub const STAIR_LANDING_M: Span = Span::new(1.3, 2.0);
/// Depth of an optional intermediate landing (flights of 4 steps or more), m.
pub const STAIR_MID_LANDING_M: Span = Span::new(0.9, 1.5);
/// Height of the `step_down` platform, m (up to the paper's 0.3 m step limit).
pub const STEP_DOWN_HEIGHT_M: Span = Span::new(0.05, 0.30);
/// Height of the `up_and_over` block, m.
pub const UP_AND_OVER_HEIGHT_M: Span = Span::new(0.08, 0.25);
/// Depth of the `up_and_over` block along the path, m.
pub const UP_AND_OVER_DEPTH_M: Span = Span::new(0.8, 2.0);
/// Largest angle between a platform or block edge and the perpendicular of the path, degrees.
pub const EDGE_YAW_DEG: f64 = 20.0;
/// Height of clutter obstacles (boxes and poles), m: up to 0.5 m.
pub const CLUTTER_HEIGHT_M: Span = Span::new(0.06, 0.50);
/// Height of drivable bumps, m: below the 0.05 m a wheel drives over (eq. 2).
pub const BUMP_HEIGHT_M: Span = Span::new(0.01, 0.045);
/// Doorway width of `narrow`, m: the robot is 0.92 m wide over its wheels.
pub const DOOR_WIDTH_M: Span = Span::new(1.0, 1.5);
/// Largest wall yaw of `narrow` and `impossible` against the path's perpendicular, degrees.
pub const WALL_YAW_DEG: f64 = 30.0;
/// Height of walls with a doorway, m: well above anything steppable.
pub const WALL_HEIGHT_M: Span = Span::new(0.6, 1.2);
/// Height of `impossible`'s wall across the map, m: above the 0.3 m step limit.
pub const HIGH_WALL_HEIGHT_M: Span = Span::new(0.36, 0.8);
/// Doorway width of `impossible`, m: narrower than the robot.
pub const TIGHT_DOOR_WIDTH_M: Span = Span::new(0.3, 0.55);
/// Height of the walls enclosing `impossible`'s goal, m: above 0.5 m.
pub const ENCLOSURE_HEIGHT_M: Span = Span::new(0.55, 1.0);
/// Spacing of the planner's headings (64 per turn), degrees; `headings` avoids them.
pub const LATTICE_STEP_DEG: f64 = 5.625;
/// Smallest distance of a `headings` yaw from the nearest lattice heading, degrees.
pub const MIN_OFF_LATTICE_DEG: f64 = 0.5;
/// Largest map, m: the longer side at most 10 m, the shorter at most 6 m.
pub const MAX_MAP_M: [f64; 2] = [10.0, 6.0];

/// Wall thickness of stairwells and corridors, m.
const WALL_THICKNESS_M: f64 = 0.15;
/// Half-width of the way kept free of clutter taller than a bump: the robot's half-width
/// over its wheels (0.46 m) plus the foot radius r_F (0.12 m) and a little.
const WAY_HALF_WIDTH_M: f64 = 0.7;
/// Clear radius around a start or goal on open ground: the driving footprint's wheels lie
/// within 0.6 m of the base centre; plus r_F. The job's check (`prepare`) is the judge.
const POSE_CLEAR_M: f64 = 1.0;
/// How far blocking obstacles reach beyond the map, m.
const BEYOND_MAP_M: f64 = 1.0;
/// Draws of one `next_case` call before giving up (rejections of the map size etc.).
pub const MAX_DRAWS: u32 = 200;

/// Why no case could be generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GenerateError {
    /// Every draw was rejected.
    #[error("class {class}, seed {seed}: no valid course in {draws} draws; the last: {reason}")]
    NoValidDraw {
        /// The class.
        class: Class,
        /// The seed.
        seed: u64,
        /// Draws tried.
        draws: u32,
        /// Why the last draw was rejected.
        reason: String,
    },
}

/// One terrain primitive of a generated case, with the comment written above it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Placed {
    /// What the primitive is for ("platform", "left wall", ...).
    pub note: String,
    /// The primitive, in world coordinates.
    pub primitive: Primitive,
}

/// A generated scenario: everything its file says.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GeneratedCase {
    /// The class.
    pub class: Class,
    /// The seed.
    pub seed: u64,
    /// Which draw of the seed's stream this is (0: the first).
    pub draw: u32,
    /// `{class}_{seed:06}`, the file stem.
    pub name: String,
    /// One line naming the drawn parameters.
    pub description: String,
    /// Map extent.
    pub map: MapExtent,
    /// Start pose.
    pub start: PoseSpec,
    /// Goal pose.
    pub goal: PoseSpec,
    /// Terrain primitives.
    pub terrain: Vec<Placed>,
    /// The right answer to the course.
    pub outcome: Outcome,
    /// Simulated-time budget of a run, s.
    pub timeout_s: f64,
    /// The drawn parameters by name (flags as 0 / 1), for the file's comments and tests.
    pub parameters: BTreeMap<&'static str, f64>,
}

impl GeneratedCase {
    /// The file name: `{class}_{seed:06}.toml`.
    pub fn file_name(&self) -> String {
        format!("{}.toml", self.name)
    }

    /// The scenario file's text (deterministic: same case, same bytes).
    pub fn to_toml(&self) -> String {
        let mut t = String::new();
        let mut line = |s: String| {
            t.push_str(&s);
            t.push('\n');
        };
        line(format!(
            "# Written by `momaro generate --class {} --seed {} --count 1` (draw {} of the seed).",
            self.class, self.seed, self.draw
        ));
        let params: Vec<String> =
            self.parameters.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        line(format!("# Drawn: {}.", params.join(", ")));
        line(format!("class = {}", quote(self.class.name())));
        line(format!("name = {}", quote(&self.name)));
        line(format!("description = {}", quote(&self.description)));
        line(String::new());
        line("[map]".into());
        line(format!("x_min = {}", num(self.map.x_min)));
        line(format!("x_max = {}", num(self.map.x_max)));
        line(format!("y_min = {}", num(self.map.y_min)));
        line(format!("y_max = {}", num(self.map.y_max)));
        for (table, p) in [("start", &self.start), ("goal", &self.goal)] {
            line(String::new());
            line(format!("[{table}]"));
            line(format!("x = {}", num(p.x)));
            line(format!("y = {}", num(p.y)));
            line(format!("yaw_deg = {}", num(p.yaw_deg)));
        }
        for placed in &self.terrain {
            line(String::new());
            line(format!("# {}", placed.note));
            line("[[terrain]]".into());
            line(format!("kind = {}", quote(placed.primitive.kind())));
            match placed.primitive {
                Primitive::Box { center, size, height, yaw_deg }
                | Primitive::Ramp { center, size, height, yaw_deg } => {
                    line(format!("center = {}", pair(center)));
                    line(format!("size = {}", pair(size)));
                    line(format!("height = {}", num(height)));
                    line(format!("yaw_deg = {}", num(yaw_deg)));
                }
                Primitive::Stairs {
                    start,
                    width,
                    steps,
                    step_depth,
                    step_height,
                    landing_depth,
                    yaw_deg,
                } => {
                    line(format!("start = {}", pair(start)));
                    line(format!("width = {}", num(width)));
                    line(format!("steps = {steps}"));
                    line(format!("step_depth = {}", num(step_depth)));
                    line(format!("step_height = {}", num(step_height)));
                    line(format!("landing_depth = {}", num(landing_depth)));
                    line(format!("yaw_deg = {}", num(yaw_deg)));
                }
                Primitive::Pole { center, radius, height } => {
                    line(format!("center = {}", pair(center)));
                    line(format!("radius = {}", num(radius)));
                    line(format!("height = {}", num(height)));
                }
            }
        }
        if let Some((step_model, foot_model)) = self.class.models() {
            line(String::new());
            line("[params]".into());
            line(format!("step_model = {}", quote(step_model.name())));
            line(format!("foot_model = {}", quote(foot_model.name())));
        }
        line(String::new());
        line("[expect]".into());
        match self.outcome {
            Outcome::Reach => {
                line("outcome = \"reach\"".into());
                line("goal_tolerance_m = 0.1".into());
                line("goal_tolerance_deg = 10.0".into());
                line("min_stability_margin_m = 0.02".into());
            }
            Outcome::NoPath => line("outcome = \"no_path\"".into()),
        }
        line(format!("timeout_s = {}", num(self.timeout_s)));
        t
    }

    /// The case's text parsed as a scenario at `dir/{file_name}`.
    ///
    /// # Errors
    /// [`ScenarioError`] if the text does not parse or validate (a generator bug).
    pub fn scenario(&self, dir: &Path) -> Result<Scenario, ScenarioError> {
        Scenario::parse(&self.to_toml(), &dir.join(self.file_name()))
    }
}

/// The stream of candidate cases of one class and seed: each call to
/// [`Draws::next_case`] continues the same random stream, so the n-th candidate is
/// always the same.
#[derive(Debug, Clone)]
pub struct Draws {
    class: Class,
    seed: u64,
    rng: Rng,
    draws: u32,
}

impl Draws {
    /// The stream of `class` from `seed`.
    pub fn new(class: Class, seed: u64) -> Self {
        Self { class, seed, rng: Rng::seeded(seed), draws: 0 }
    }

    /// The next draw that parses as a scenario and fits the map limit.
    ///
    /// # Errors
    /// [`GenerateError::NoValidDraw`] after [`MAX_DRAWS`] rejected draws in a row.
    pub fn next_case(&mut self) -> Result<GeneratedCase, GenerateError> {
        let mut reason = String::new();
        for _ in 0..MAX_DRAWS {
            let draw = self.draws;
            self.draws += 1;
            match draw_case(self.class, self.seed, draw, &mut self.rng) {
                Ok(case) => match case.scenario(Path::new("")) {
                    Ok(_) => return Ok(case),
                    Err(e) => reason = e.to_string(),
                },
                Err(Reject(r)) => reason = r,
            }
        }
        Err(GenerateError::NoValidDraw {
            class: self.class,
            seed: self.seed,
            draws: MAX_DRAWS,
            reason,
        })
    }
}

/// The first valid draw of `class` from `seed` (without the robot's standability check,
/// which `jobs::generate` adds).
///
/// # Errors
/// [`GenerateError::NoValidDraw`].
pub fn generate(class: Class, seed: u64) -> Result<GeneratedCase, GenerateError> {
    Draws::new(class, seed).next_case()
}

/// Why a draw was rejected.
#[derive(Debug)]
struct Reject(String);

fn draw_case(class: Class, seed: u64, draw: u32, rng: &mut Rng) -> Result<GeneratedCase, Reject> {
    let course = match class {
        Class::Stairs => stairs(rng)?,
        Class::StepDown => step_down(rng)?,
        Class::UpAndOver => up_and_over(rng)?,
        Class::Clutter => clutter(rng)?,
        Class::Narrow => narrow(rng)?,
        Class::Headings => headings(rng)?,
        Class::Mixed => mixed(rng)?,
        Class::Impossible => impossible(rng)?,
    };
    let map = course.map;
    let (long, short) = {
        let (a, b) = (map.x_max - map.x_min, map.y_max - map.y_min);
        (a.max(b), a.min(b))
    };
    if long > MAX_MAP_M[0] + 1e-9 || short > MAX_MAP_M[1] + 1e-9 {
        return Err(Reject(format!(
            "map {long:.1} m x {short:.1} m exceeds {} m x {} m",
            MAX_MAP_M[0], MAX_MAP_M[1]
        )));
    }
    let timeout_s = match course.outcome {
        Outcome::Reach => {
            // 60 s, 40 s per planned step (four per height edge, one per leg; the
            // platform's 4 steps take 146 s of keyframes) and 10 s per metre of course;
            // rounded up to whole 10 s.
            let t = 60.0 + 4.0 * 40.0 * f64::from(course.edges) + 10.0 * course.length_m;
            (t / 10.0).ceil() * 10.0
        }
        Outcome::NoPath => 60.0,
    };
    Ok(GeneratedCase {
        class,
        seed,
        draw,
        name: format!("{}_{seed:06}", class.name()),
        description: course.description,
        map,
        start: course.start,
        goal: course.goal,
        terrain: course.terrain,
        outcome: course.outcome,
        timeout_s,
        parameters: course.parameters,
    })
}

/// A drawn course before it becomes a case.
struct Course {
    description: String,
    map: MapExtent,
    start: PoseSpec,
    goal: PoseSpec,
    terrain: Vec<Placed>,
    outcome: Outcome,
    /// Height edges a run must step, each four steps (for the timeout).
    edges: u32,
    /// Length of the course, m (for the timeout).
    length_m: f64,
    parameters: BTreeMap<&'static str, f64>,
}

// ---------------------------------------------------------------------------------------
// Numbers and text.

fn round_to(v: f64, decimals: i32) -> f64 {
    let f = 10f64.powi(decimals);
    // `+ 0.0` turns −0 into 0.
    (v * f).round() / f + 0.0
}

/// Positions and sizes are written to the millimetre.
fn mm(v: f64) -> f64 {
    round_to(v, 3)
}

/// An angle in degrees wrapped to [−180, 180) and rounded to 0.1°.
fn deg(v: f64) -> f64 {
    let w = round_to((v + 180.0).rem_euclid(360.0) - 180.0, 1);
    if w >= 180.0 { w - 360.0 } else { w }
}

/// A TOML float: always with a decimal point or exponent.
fn num(v: f64) -> String {
    format!("{:?}", v + 0.0)
}

fn pair(p: [f64; 2]) -> String {
    format!("[{}, {}]", num(p[0]), num(p[1]))
}

/// A TOML basic string.
fn quote(s: &str) -> String {
    let mut q = String::with_capacity(s.len() + 2);
    q.push('"');
    for c in s.chars() {
        match c {
            '"' => q.push_str("\\\""),
            '\\' => q.push_str("\\\\"),
            c if c.is_control() => q.push_str(&format!("\\u{:04X}", u32::from(c))),
            c => q.push(c),
        }
    }
    q.push('"');
    q
}

/// Distance of a yaw from the nearest multiple of [`LATTICE_STEP_DEG`], degrees.
pub fn off_lattice_deg(yaw_deg: f64) -> f64 {
    let r = yaw_deg.rem_euclid(LATTICE_STEP_DEG);
    r.min(LATTICE_STEP_DEG - r)
}

// ---------------------------------------------------------------------------------------
// Geometry: the course frame and the builder of primitives in it.

/// Rotates `p` by `yaw_deg` and adds `origin` (a point of a sub-frame in its parent).
fn sub(origin: [f64; 2], yaw_deg: f64, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = yaw_deg.to_radians().sin_cos();
    [origin[0] + c * p[0] - s * p[1], origin[1] + s * p[0] + c * p[1]]
}

/// Coordinates of `p` in a sub-frame at `origin` turned by `yaw_deg`.
fn in_sub(origin: [f64; 2], yaw_deg: f64, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = yaw_deg.to_radians().sin_cos();
    let (dx, dy) = (p[0] - origin[0], p[1] - origin[1]);
    [c * dx + s * dy, -s * dx + c * dy]
}

fn polyline_distance(p: [f64; 2], way: &[[f64; 2]]) -> f64 {
    way.windows(2)
        .map(|w| crate::geometry::segment_distance(p, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

fn polyline_length(way: &[[f64; 2]]) -> f64 {
    way.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum()
}

/// The course frame in the world: its origin is the world origin, turned by a whole
/// number of quarter turns (exact) or by any yaw.
#[derive(Debug, Clone, Copy)]
enum Frame {
    Quarter(u8),
    Yaw(f64),
}

impl Frame {
    fn yaw_deg(self) -> f64 {
        match self {
            Frame::Quarter(q) => 90.0 * f64::from(q),
            Frame::Yaw(y) => y,
        }
    }

    fn point(self, p: [f64; 2]) -> [f64; 2] {
        match self {
            Frame::Quarter(q) => match q % 4 {
                0 => p,
                1 => [-p[1], p[0]],
                2 => [-p[0], -p[1]],
                _ => [p[1], -p[0]],
            },
            Frame::Yaw(y) => sub([0.0, 0.0], y, p),
        }
    }

    /// The inverse of [`Frame::point`]: a world point in the course frame.
    fn local(self, p: [f64; 2]) -> [f64; 2] {
        match self {
            Frame::Quarter(q) => Frame::Quarter((4 - q % 4) % 4).point(p),
            Frame::Yaw(y) => in_sub([0.0, 0.0], y, p),
        }
    }
}

/// Builds a course in its local frame; writes world coordinates, rounded as written.
struct Builder {
    frame: Frame,
    terrain: Vec<Placed>,
    parameters: BTreeMap<&'static str, f64>,
}

impl Builder {
    fn new(frame: Frame) -> Self {
        Self { frame, terrain: Vec::new(), parameters: BTreeMap::new() }
    }

    fn param(&mut self, name: &'static str, v: f64) -> f64 {
        self.parameters.insert(name, v);
        v
    }

    fn at(&self, p: [f64; 2]) -> [f64; 2] {
        let w = self.frame.point(p);
        [mm(w[0]), mm(w[1])]
    }

    fn pose(&self, p: [f64; 2], local_yaw_deg: f64) -> PoseSpec {
        let [x, y] = self.at(p);
        PoseSpec { x, y, yaw_deg: deg(self.frame.yaw_deg() + local_yaw_deg) }
    }

    fn add_box(&mut self, note: String, center: [f64; 2], size: [f64; 2], height: f64, yaw: f64) {
        let primitive = Primitive::Box {
            center: self.at(center),
            size: [mm(size[0]), mm(size[1])],
            height: mm(height),
            yaw_deg: deg(self.frame.yaw_deg() + yaw),
        };
        self.terrain.push(Placed { note, primitive });
    }

    fn add_pole(&mut self, note: String, center: [f64; 2], radius: f64, height: f64) {
        let primitive =
            Primitive::Pole { center: self.at(center), radius: mm(radius), height: mm(height) };
        self.terrain.push(Placed { note, primitive });
    }

    #[allow(clippy::too_many_arguments)]
    fn add_stairs(
        &mut self,
        note: String,
        start: [f64; 2],
        width: f64,
        steps: u32,
        tread: f64,
        rise: f64,
        landing: f64,
        yaw: f64,
    ) {
        let primitive = Primitive::Stairs {
            start: self.at(start),
            width: mm(width),
            steps,
            step_depth: mm(tread),
            step_height: mm(rise),
            landing_depth: mm(landing),
            yaw_deg: deg(self.frame.yaw_deg() + yaw),
        };
        self.terrain.push(Placed { note, primitive });
    }

    /// The world map covering the local points `corners` (their bounding box after the
    /// frame's turn) plus `margin`, rounded outward to 0.1 m.
    fn map(&self, corners: &[[f64; 2]], margin: f64) -> MapExtent {
        let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for &p in corners {
            let [x, y] = self.frame.point(p);
            b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
        }
        let down = |v: f64| round_to(((v - margin) * 10.0 + 1e-6).floor() / 10.0, 1);
        let up = |v: f64| round_to(((v + margin) * 10.0 - 1e-6).ceil() / 10.0, 1);
        MapExtent { x_min: down(b[0]), y_min: down(b[1]), x_max: up(b[2]), y_max: up(b[3]) }
    }

    /// The corners of a world map in the course frame.
    fn local_corners(&self, map: &MapExtent) -> [[f64; 2]; 4] {
        rect(map.x_min, map.x_max, map.y_min, map.y_max).map(|p| self.frame.local(p))
    }

    #[allow(clippy::too_many_arguments)]
    fn finish(
        self,
        description: String,
        map: MapExtent,
        start: PoseSpec,
        goal: PoseSpec,
        outcome: Outcome,
        edges: u32,
        length_m: f64,
    ) -> Course {
        Course {
            description,
            map,
            start,
            goal,
            terrain: self.terrain,
            outcome,
            edges,
            length_m,
            parameters: self.parameters,
        }
    }
}

/// A rectangle of the course frame: `[x0, x1] × [y0, y1]` as its corners.
fn rect(x0: f64, x1: f64, y0: f64, y1: f64) -> [[f64; 2]; 4] {
    [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// The extent of `corners` in a sub-frame at `origin` turned by `yaw_deg`:
/// `[x_min, x_max, y_min, y_max]`.
fn extent_in(origin: [f64; 2], yaw_deg: f64, corners: &[[f64; 2]]) -> [f64; 4] {
    let mut e = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
    for &c in corners {
        let [x, y] = in_sub(origin, yaw_deg, c);
        e = [e[0].min(x), e[1].max(x), e[2].min(y), e[3].max(y)];
    }
    e
}

fn quarter(rng: &mut Rng) -> Frame {
    Frame::Quarter(rng.below(4) as u8)
}

/// Two walls along the course's x over the whole map and beyond, `clear` apart.
fn corridor_walls(b: &mut Builder, map: &[[f64; 2]; 4], clear: f64, height: f64) {
    let e = extent_in([0.0, 0.0], 0.0, map);
    let (x0, x1) = (e[0] - BEYOND_MAP_M, e[1] + BEYOND_MAP_M);
    let t = WALL_THICKNESS_M;
    for (side, s) in [("left", 1.0), ("right", -1.0)] {
        b.add_box(
            format!("{side} corridor wall"),
            [(x0 + x1) / 2.0, s * (clear / 2.0 + t / 2.0)],
            [x1 - x0, t],
            height,
            0.0,
        );
    }
}

/// A wall through `origin` (course frame) whose face normal lies at `yaw_deg` from the
/// course's +x, crossing the whole map (`map`, its corners) and 1 m beyond; with a
/// doorway `door` m wide centred on `origin` (none for 0).
#[allow(clippy::too_many_arguments)]
fn wall_across(
    b: &mut Builder,
    map: &[[f64; 2]; 4],
    origin: [f64; 2],
    yaw_deg: f64,
    thickness: f64,
    height: f64,
    door: f64,
    name: &str,
) {
    let e = extent_in(origin, yaw_deg, map);
    let (lo, hi) = (e[2] - BEYOND_MAP_M, e[3] + BEYOND_MAP_M);
    if door <= 0.0 {
        b.add_box(
            name.to_owned(),
            sub(origin, yaw_deg, [0.0, (lo + hi) / 2.0]),
            [thickness, hi - lo],
            height,
            yaw_deg,
        );
        return;
    }
    for (side, from, to) in [("left", door / 2.0, hi), ("right", lo, -door / 2.0)] {
        b.add_box(
            format!("{name}, {side} of the doorway"),
            sub(origin, yaw_deg, [0.0, (from + to) / 2.0]),
            [thickness, to - from],
            height,
            yaw_deg,
        );
    }
}

/// One random clutter obstacle: (is a pole, size (a pole: radius twice), yaw, height,
/// radius of a disc covering its footprint).
fn clutter_obstacle(rng: &mut Rng) -> (bool, [f64; 2], f64, f64, f64) {
    let pole = rng.chance(0.4);
    let height = CLUTTER_HEIGHT_M.draw(rng, 3);
    if pole {
        let r = round_to(rng.range(0.03, 0.12), 3);
        (true, [r, r], 0.0, height, r)
    } else {
        let size = [round_to(rng.range(0.2, 0.8), 3), round_to(rng.range(0.2, 0.8), 3)];
        let yaw = round_to(rng.range(0.0, 180.0), 1);
        (false, size, yaw, height, size[0].hypot(size[1]) / 2.0)
    }
}

/// Scatters `n` clutter obstacles over `area` (course frame), none within the way's
/// half-width of the polyline `way` nor within [`POSE_CLEAR_M`] of `poses`; returns the
/// boxes, poles and the lowest and highest placed.
fn scatter(
    b: &mut Builder,
    rng: &mut Rng,
    n: u32,
    area: [f64; 4],
    way: &[[f64; 2]],
    poses: &[[f64; 2]],
) -> (u32, u32, f64, f64) {
    let (mut boxes, mut poles, mut lo, mut hi) = (0, 0, f64::INFINITY, 0.0f64);
    for k in 0..n {
        let (pole, size, yaw, height, radius) = clutter_obstacle(rng);
        for _ in 0..40 {
            let c = [
                round_to(rng.range(area[0], area[1]), 3),
                round_to(rng.range(area[2], area[3]), 3),
            ];
            let clear_way = way.len() < 2 || polyline_distance(c, way) >= WAY_HALF_WIDTH_M + radius;
            let clear_poses =
                poses.iter().all(|p| (c[0] - p[0]).hypot(c[1] - p[1]) >= POSE_CLEAR_M + radius);
            if clear_way && clear_poses {
                if pole {
                    b.add_pole(format!("clutter {}: pole", k + 1), c, size[0], height);
                    poles += 1;
                } else {
                    b.add_box(format!("clutter {}: box", k + 1), c, size, height, yaw);
                    boxes += 1;
                }
                lo = lo.min(height);
                hi = hi.max(height);
                break;
            }
        }
    }
    (boxes, poles, lo, hi)
}

fn reject_unless(ok: bool, reason: impl FnOnce() -> String) -> Result<(), Reject> {
    if ok { Ok(()) } else { Err(Reject(reason())) }
}

// ---------------------------------------------------------------------------------------
// The classes.

fn stairs(rng: &mut Rng) -> Result<Course, Reject> {
    let up = rng.chance(0.5);
    let steps = rng.int_range(STAIR_STEPS[0], STAIR_STEPS[1]);
    let rise = STAIR_RISE_M.draw(rng, 3);
    let tread = STAIR_TREAD_M.draw(rng, 3);
    let width = STAIR_WIDTH_M.draw(rng, 2);
    let landing = STAIR_LANDING_M.draw(rng, 2);
    let walls = rng.chance(0.5);
    let mid = if steps >= 4 && rng.chance(0.5) {
        Some((rng.int_range(2, steps - 2), STAIR_MID_LANDING_M.draw(rng, 2)))
    } else {
        None
    };
    let ground_d = round_to(rng.range(0.9, 1.3), 2);
    let ground_y = round_to(rng.range(-0.2, 0.2), 2);
    let ground_yaw = round_to(rng.range(-30.0, 30.0), 1);
    let landing_yaw = round_to(rng.range(-10.0, 10.0), 1);
    let mid_depth = mid.map_or(0.0, |m| m.1);
    let run = f64::from(steps) * tread + mid_depth + landing;
    let t = WALL_THICKNESS_M;
    let half = width / 2.0 + if walls { t } else { 0.0 };
    let back = run + if walls { t } else { 0.0 };
    let mut corners = rect(0.0, back, -half, half).to_vec();
    corners.extend(rect(-ground_d - 0.8, -ground_d + 0.8, ground_y - 0.8, ground_y + 0.8));
    // The flight's direction: any yaw whose map fits; after 32 tries the nearest quarter
    // turn (every course fits along an axis).
    let mut yaw = 0.0;
    let mut fits = false;
    for _ in 0..32 {
        yaw = round_to(rng.range(-180.0, 180.0), 1);
        let map = Builder::new(Frame::Yaw(yaw)).map(&corners, 0.3);
        let (a, b) = (map.x_max - map.x_min, map.y_max - map.y_min);
        if a.max(b) <= MAX_MAP_M[0] && a.min(b) <= MAX_MAP_M[1] {
            fits = true;
            break;
        }
    }
    if !fits {
        yaw = deg((yaw / 90.0).round() * 90.0);
    }
    let frame = if yaw.rem_euclid(90.0) == 0.0 {
        Frame::Quarter(((yaw / 90.0).round() as i32).rem_euclid(4) as u8)
    } else {
        Frame::Yaw(yaw)
    };
    let mut b = Builder::new(frame);
    b.param("up", if up { 1.0 } else { 0.0 });
    b.param("steps", f64::from(steps));
    b.param("rise_m", rise);
    b.param("tread_m", tread);
    b.param("width_m", width);
    b.param("top_landing_m", landing);
    b.param("mid_landing_m", mid_depth);
    b.param("mid_landing_after", mid.map_or(0.0, |m| f64::from(m.0)));
    b.param("walls", if walls { 1.0 } else { 0.0 });
    b.param("yaw_deg", yaw);
    let (label, start) = match mid {
        Some((k1, depth)) => {
            b.add_stairs(
                format!("lower flight: steps 1 to {k1}, then the intermediate landing"),
                [0.0, 0.0],
                width,
                k1,
                tread,
                rise,
                depth,
                0.0,
            );
            // Steps 1..k1 of the full flight below lie under the lower flight (lower
            // than it), so the union is the lower flight, the landing, then steps k1+1.. .
            (format!("upper flight: steps {} to {steps} and the top landing", k1 + 1), [depth, 0.0])
        }
        None => ("the flight and its top landing".into(), [0.0, 0.0]),
    };
    b.add_stairs(label, start, width, steps, tread, rise, landing, 0.0);
    let top = f64::from(steps) * rise;
    if walls {
        let h = round_to(top + 0.6, 2);
        for (side, s) in [("left", 1.0), ("right", -1.0)] {
            b.add_box(
                format!("{side} stairwell wall"),
                [back / 2.0, s * (width / 2.0 + t / 2.0)],
                [back, t],
                h,
                0.0,
            );
        }
        b.add_box(
            "back wall of the top landing".into(),
            [run + t / 2.0, 0.0],
            [t, width + 2.0 * t],
            h,
            0.0,
        );
    }
    let map = b.map(&corners, 0.3);
    let ground = [-ground_d, ground_y];
    let top_pose = [run - landing / 2.0, 0.0];
    let (start, goal) = if up {
        (b.pose(ground, ground_yaw), b.pose(top_pose, landing_yaw))
    } else {
        (b.pose(top_pose, 180.0 + landing_yaw), b.pose(ground, 180.0 + ground_yaw))
    };
    let mut description = format!(
        "stairs {}: {steps} steps of {rise:.3} m rise on {tread:.3} m tread, {width:.2} m wide",
        if up { "up" } else { "down" }
    );
    if let Some((k1, depth)) = mid {
        description += &format!(", {depth:.2} m landing after step {k1}");
    }
    description += &format!(
        ", {landing:.2} m top landing, {}, yaw {:.1}°",
        if walls { "walls" } else { "open sides" },
        yaw
    );
    let length = ground_d + run - landing / 2.0;
    Ok(b.finish(description, map, start, goal, Outcome::Reach, steps, length))
}

/// The common layout of `step_down` and `up_and_over`: a quarter-turned course whose
/// edges cross the whole map at `edge_yaw` (degrees from the path's perpendicular),
/// optionally between corridor walls `walls` m apart; start `d_start` m before the first
/// edge, goal `d_goal` m beyond the last.
struct EdgeCourse {
    b: Builder,
    corners: [[f64; 2]; 4],
    edge_yaw: f64,
    walls: Option<f64>,
    d_start: f64,
    d_goal: f64,
    start_y: f64,
    goal_y: f64,
    start_yaw: f64,
    goal_yaw: f64,
}

fn edge_course(rng: &mut Rng, far_edge: f64, d_goal: [f64; 2]) -> EdgeCourse {
    let frame = quarter(rng);
    let edge_yaw = round_to(rng.range(-EDGE_YAW_DEG, EDGE_YAW_DEG), 1);
    let w_map = round_to(rng.range(3.0, 5.0), 1);
    let walls = rng.chance(0.5).then(|| round_to(rng.range(1.8, (w_map - 0.6).min(3.0)), 2));
    let d_start = round_to(rng.range(1.1, 1.6), 2);
    let d_goal = round_to(rng.range(d_goal[0], d_goal[1]), 2);
    // Sideways room: the robot turns on the spot 0.75 m from a corridor wall.
    let lat = walls.map_or(0.6, |c| (c / 2.0 - 0.75).min(0.6));
    let start_y = round_to(rng.range(-lat, lat), 2);
    let goal_y = round_to(rng.range(-lat, lat), 2);
    let start_yaw = round_to(rng.range(-90.0, 90.0), 1);
    let goal_yaw = round_to(rng.range(-45.0, 45.0), 1);
    // The far edge's x at the course centre line, pushed out by its yaw.
    let far = far_edge / edge_yaw.to_radians().cos();
    let corners = rect(-d_start - 1.0, far + d_goal + 1.0, -w_map / 2.0, w_map / 2.0);
    let mut b = Builder::new(frame);
    b.param("edge_yaw_deg", edge_yaw);
    b.param("map_width_m", w_map);
    b.param("corridor_m", walls.unwrap_or(0.0));
    b.param("heading_deg", frame.yaw_deg());
    EdgeCourse {
        b,
        corners,
        edge_yaw,
        walls,
        d_start,
        d_goal,
        start_y,
        goal_y,
        start_yaw,
        goal_yaw,
    }
}

fn step_down(rng: &mut Rng) -> Result<Course, Reject> {
    let h = STEP_DOWN_HEIGHT_M.draw(rng, 3);
    let mut c = edge_course(rng, 0.0, [1.2, 2.5]);
    c.b.param("height_m", h);
    let map = c.b.map(&c.corners, 0.0);
    let corners = c.b.local_corners(&map);
    // The platform: everything behind the edge through the origin, across the map.
    let e = extent_in([0.0, 0.0], c.edge_yaw, &corners);
    let back = -e[0] + BEYOND_MAP_M;
    let (lo, hi) = (e[2] - BEYOND_MAP_M, e[3] + BEYOND_MAP_M);
    c.b.add_box(
        "the platform the robot starts on; its edge crosses the map".into(),
        sub([0.0, 0.0], c.edge_yaw, [-back / 2.0, (lo + hi) / 2.0]),
        [back, hi - lo],
        h,
        c.edge_yaw,
    );
    if let Some(clear) = c.walls {
        corridor_walls(&mut c.b, &corners, clear, 0.8);
    }
    let start = c.b.pose([-c.d_start, c.start_y], c.start_yaw);
    let goal = c.b.pose([c.d_goal, c.goal_y], c.goal_yaw);
    let description = format!(
        "step down: {h:.3} m platform, edge at {:.1}° to the path, {}, heading {:.0}°",
        c.edge_yaw,
        c.walls.map_or("full width".to_owned(), |w| format!("walls {w:.2} m apart")),
        c.b.frame.yaw_deg()
    );
    let length = c.d_start + c.d_goal;
    Ok(c.b.finish(description, map, start, goal, Outcome::Reach, 1, length))
}

fn up_and_over(rng: &mut Rng) -> Result<Course, Reject> {
    let h = UP_AND_OVER_HEIGHT_M.draw(rng, 3);
    let depth = UP_AND_OVER_DEPTH_M.draw(rng, 2);
    let mut c = edge_course(rng, depth, [1.0, 2.0]);
    c.b.param("height_m", h);
    c.b.param("depth_m", depth);
    let map = c.b.map(&c.corners, 0.0);
    let corners = c.b.local_corners(&map);
    let e = extent_in([0.0, 0.0], c.edge_yaw, &corners);
    let (lo, hi) = (e[2] - BEYOND_MAP_M, e[3] + BEYOND_MAP_M);
    c.b.add_box(
        "the block across the path".into(),
        sub([0.0, 0.0], c.edge_yaw, [depth / 2.0, (lo + hi) / 2.0]),
        [depth, hi - lo],
        h,
        c.edge_yaw,
    );
    if let Some(clear) = c.walls {
        corridor_walls(&mut c.b, &corners, clear, 0.8);
    }
    let far = depth / c.edge_yaw.to_radians().cos();
    let start = c.b.pose([-c.d_start, c.start_y], c.start_yaw);
    let goal = c.b.pose([far + c.d_goal, c.goal_y], c.goal_yaw);
    let description = format!(
        "up and over: {h:.3} m block, {depth:.2} m deep, edges at {:.1}° to the path, {}, heading {:.0}°",
        c.edge_yaw,
        c.walls.map_or("full width".to_owned(), |w| format!("walls {w:.2} m apart")),
        c.b.frame.yaw_deg()
    );
    let length = c.d_start + far + c.d_goal;
    Ok(c.b.finish(description, map, start, goal, Outcome::Reach, 2, length))
}

fn clutter(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let l = round_to(rng.range(6.0, 9.0), 1);
    let w = round_to(rng.range(4.0, 6.0), 1);
    let lat = w / 2.0 - 1.0;
    let start = [1.0, round_to(rng.range(-lat, lat), 2)];
    let goal = [l - 1.0, round_to(rng.range(-lat, lat), 2)];
    let via = [round_to(l / 2.0 + rng.range(-0.5, 0.5), 2), round_to(rng.range(-lat, lat), 2)];
    let way = [start, via, goal];
    let start_yaw = round_to(rng.range(-180.0, 180.0), 1);
    let goal_yaw = round_to(rng.range(-180.0, 180.0), 1);
    let n = rng.int_range(6, 14);
    let n_bumps = rng.int_range(3, 8);
    let mut b = Builder::new(frame);
    b.param("length_m", l);
    b.param("width_m", w);
    let area = [0.3, l - 0.3, -w / 2.0 + 0.3, w / 2.0 - 0.3];
    let (boxes, poles, lo, hi) = scatter(&mut b, rng, n, area, &way, &[start, goal]);
    for k in 0..n_bumps {
        let h = BUMP_HEIGHT_M.draw(rng, 3);
        let size = [round_to(rng.range(0.3, 1.2), 3), round_to(rng.range(0.3, 1.2), 3)];
        let c =
            [round_to(rng.range(area[0], area[1]), 3), round_to(rng.range(area[2], area[3]), 3)];
        let yaw = round_to(rng.range(0.0, 180.0), 1);
        b.add_box(format!("bump {}: drivable", k + 1), c, size, h, yaw);
    }
    b.param("obstacles", f64::from(boxes + poles));
    b.param("bumps", f64::from(n_bumps));
    b.param("tallest_m", hi);
    let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
    let description = format!(
        "clutter: {} obstacles ({boxes} boxes, {poles} poles, {:.2}-{hi:.2} m tall), {n_bumps} bumps under 0.05 m, {l:.1} m x {w:.1} m",
        boxes + poles,
        if lo.is_finite() { lo } else { 0.0 }
    );
    let (s, g) = (b.pose(start, start_yaw), b.pose(goal, goal_yaw));
    Ok(b.finish(description, map, s, g, Outcome::Reach, 2, polyline_length(&way)))
}

fn narrow(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let door = DOOR_WIDTH_M.draw(rng, 2);
    let wall_yaw = round_to(rng.range(-WALL_YAW_DEG, WALL_YAW_DEG), 1);
    let thickness = round_to(rng.range(0.1, 0.3), 2);
    let height = WALL_HEIGHT_M.draw(rng, 2);
    let corridor = rng.chance(0.35).then(|| round_to(rng.range(1.0, 2.0), 2));
    let w = round_to(rng.range(3.5, 5.0), 1);
    let door_y = round_to(rng.range(-0.5, 0.5), 2);
    let reach = corridor.map_or(0.0, |c| c / 2.0) + thickness / 2.0;
    // Start and goal anywhere across the map, 1.0-1.6 m before and behind the wall (and
    // the corridor), measured along the wall's normal.
    let origin = [0.0, door_y];
    let lat = w / 2.0 - POSE_CLEAR_M;
    let (sin, cos) = wall_yaw.to_radians().sin_cos();
    let place = |rng: &mut Rng, side: f64| {
        let y = round_to(rng.range(-lat, lat), 2);
        let normal = side * (reach + rng.range(1.0, 1.6));
        [round_to((normal - (y - door_y) * sin) / cos, 2), y]
    };
    let s = place(rng, -1.0);
    let g = place(rng, 1.0);
    let corners = rect(s[0] - POSE_CLEAR_M, g[0] + POSE_CLEAR_M, -w / 2.0, w / 2.0);
    let mut b = Builder::new(frame);
    b.param("door_m", door);
    b.param("wall_yaw_deg", wall_yaw);
    b.param("wall_height_m", height);
    b.param("wall_thickness_m", thickness);
    b.param("corridor_m", corridor.unwrap_or(0.0));
    let map = b.map(&corners, 0.0);
    let corners = b.local_corners(&map);
    wall_across(&mut b, &corners, origin, wall_yaw, thickness, height, door, "wall");
    if let Some(len) = corridor {
        for (side, sgn) in [("left", 1.0), ("right", -1.0)] {
            b.add_box(
                format!("{side} corridor wall through the doorway"),
                sub(origin, wall_yaw, [0.0, sgn * (door / 2.0 + thickness / 2.0)]),
                [len, thickness],
                height,
                wall_yaw,
            );
        }
    }
    let start = b.pose(s, wall_yaw + round_to(rng.range(-45.0, 45.0), 1));
    let goal = b.pose(g, wall_yaw + round_to(rng.range(-45.0, 45.0), 1));
    let description = format!(
        "narrow: {door:.2} m doorway in a {height:.2} m wall at {wall_yaw:.1}° to the path{}",
        corridor.map_or(String::new(), |c| format!(", a {c:.2} m corridor through it"))
    );
    let length = (g[0] - s[0]).hypot(g[1] - s[1]);
    Ok(b.finish(description, map, start, goal, Outcome::Reach, 0, length + 3.0))
}

/// A yaw uniform over the turn and at least [`MIN_OFF_LATTICE_DEG`] from the lattice.
fn off_lattice_yaw(rng: &mut Rng) -> f64 {
    let k = rng.below(64) as f64;
    let off = rng.range(MIN_OFF_LATTICE_DEG + 0.05, LATTICE_STEP_DEG - MIN_OFF_LATTICE_DEG - 0.05);
    deg(-180.0 + k * LATTICE_STEP_DEG + off)
}

fn headings(rng: &mut Rng) -> Result<Course, Reject> {
    let l = round_to(rng.range(5.0, 8.0), 1);
    let w = round_to(rng.range(4.0, 6.0), 1);
    let pick = |rng: &mut Rng| {
        [
            round_to(rng.range(1.0, l - 1.0), 2),
            round_to(rng.range(-w / 2.0 + 1.0, w / 2.0 - 1.0), 2),
        ]
    };
    let start = pick(rng);
    let mut goal = pick(rng);
    let dist = |g: [f64; 2]| (g[0] - start[0]).hypot(g[1] - start[1]);
    for _ in 0..20 {
        if dist(goal) >= 2.0 {
            break;
        }
        goal = pick(rng);
    }
    let apart = dist(goal);
    reject_unless(apart >= 2.0, || format!("start and goal only {apart:.2} m apart"))?;
    let start_yaw = off_lattice_yaw(rng);
    let goal_yaw = off_lattice_yaw(rng);
    let obstacles = if rng.chance(0.5) { rng.int_range(1, 4) } else { 0 };
    let mut b = Builder::new(Frame::Quarter(0));
    b.param("start_yaw_deg", start_yaw);
    b.param("goal_yaw_deg", goal_yaw);
    b.param("distance_m", round_to(apart, 2));
    let area = [0.3, l - 0.3, -w / 2.0 + 0.3, w / 2.0 - 0.3];
    let (boxes, poles, _, _) =
        scatter(&mut b, rng, obstacles, area, &[start, goal], &[start, goal]);
    b.param("obstacles", f64::from(boxes + poles));
    let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
    let [sx, sy] = b.at(start);
    let [gx, gy] = b.at(goal);
    let s = PoseSpec { x: sx, y: sy, yaw_deg: start_yaw };
    let g = PoseSpec { x: gx, y: gy, yaw_deg: goal_yaw };
    let description = format!(
        "headings: start yaw {start_yaw:.1}°, goal yaw {goal_yaw:.1}° (off the {LATTICE_STEP_DEG}° lattice), {apart:.2} m apart, {}",
        match boxes + poles {
            0 => "open ground".to_owned(),
            n => format!("{n} obstacles"),
        }
    );
    Ok(b.finish(description, map, s, g, Outcome::Reach, 0, apart + 2.0))
}

fn mixed(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let w = round_to(rng.range(3.5, 5.0), 1);
    let lat = w / 2.0 - 1.0;
    let start = [1.0, round_to(rng.range(-0.6, 0.6), 2)];
    let lane = round_to(rng.range(-lat, lat), 2);
    let climb_at = round_to(rng.range(4.0, 4.6), 2);
    let n_clutter = rng.int_range(2, 4);
    let block = rng.chance(0.5);
    // Across the map (its half-width as written, rounded up to 0.1 m) and 1 m beyond.
    let across = 2.0 * ((w / 2.0 * 10.0 - 1e-6).ceil() / 10.0 + BEYOND_MAP_M);
    let mut b = Builder::new(frame);
    b.param("map_width_m", w);
    b.param("heading_deg", frame.yaw_deg());
    let (plateau_end, drop, edges, climb) = if block {
        let h = UP_AND_OVER_HEIGHT_M.draw(rng, 3);
        let depth = round_to(rng.range(1.5, 2.3), 2);
        b.param("block_height_m", h);
        b.param("block_depth_m", depth);
        b.add_box(
            "the block to climb, across the map; its far edge is the step down".into(),
            [climb_at + depth / 2.0, 0.0],
            [depth, across],
            h,
            0.0,
        );
        (climb_at + depth, h, 2, format!("a {h:.3} m block {depth:.2} m deep"))
    } else {
        let steps = rng.int_range(2, 3);
        let rise = round_to(rng.range(STAIR_RISE_M.lo, (0.3 / f64::from(steps)).min(0.15)), 3);
        let tread = round_to(rng.range(0.30, STAIR_TREAD_M.hi), 3);
        let plateau = round_to(rng.range(1.2, 1.8), 2);
        b.param("steps", f64::from(steps));
        b.param("rise_m", rise);
        b.param("tread_m", tread);
        b.param("plateau_m", plateau);
        b.add_stairs(
            "stairs up to a plateau, across the map; its far edge is the step down".into(),
            [climb_at, 0.0],
            across,
            steps,
            tread,
            rise,
            plateau,
            0.0,
        );
        let top = f64::from(steps) * rise;
        (
            climb_at + f64::from(steps) * tread + plateau,
            top,
            steps + 1,
            format!(
                "{steps} steps of {rise:.3} m on {tread:.3} m tread to a {plateau:.2} m plateau"
            ),
        )
    };
    let goal = [round_to(plateau_end + rng.range(1.1, 1.4), 2), round_to(rng.range(-0.6, 0.6), 2)];
    let l = goal[0] + 1.0;
    let way = [start, [1.9, lane], [3.6, lane], [climb_at, lane]];
    let area = [1.9, 3.6, -w / 2.0 + 0.3, w / 2.0 - 0.3];
    let (boxes, poles, _, _) = scatter(&mut b, rng, n_clutter, area, &way, &[start]);
    b.param("obstacles", f64::from(boxes + poles));
    b.param("step_down_m", drop);
    let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
    let s = b.pose(start, round_to(rng.range(-45.0, 45.0), 1));
    let g = b.pose(goal, round_to(rng.range(-45.0, 45.0), 1));
    let description = format!(
        "mixed: {} clutter obstacles, then {climb}, step down {drop:.3} m, {l:.1} m course, heading {:.0}°",
        boxes + poles,
        frame.yaw_deg()
    );
    Ok(b.finish(description, map, s, g, Outcome::Reach, edges, goal[0] - start[0]))
}

fn impossible(rng: &mut Rng) -> Result<Course, Reject> {
    let frame = quarter(rng);
    let variant = rng.below(3);
    let mut b = Builder::new(frame);
    b.param("variant", variant as f64);
    let start_yaw = round_to(rng.range(-180.0, 180.0), 1);
    let goal_yaw = round_to(rng.range(-180.0, 180.0), 1);
    match variant {
        0 => {
            let inner = round_to(rng.range(1.6, 2.2), 2);
            let t = round_to(rng.range(0.15, 0.3), 2);
            let height = ENCLOSURE_HEIGHT_M.draw(rng, 2);
            let turn = round_to(rng.range(0.0, 90.0), 1);
            let radius = (inner / 2.0 + t) * std::f64::consts::SQRT_2;
            // Room for the start 1.6 m before the enclosure's circle.
            let l = (rng.range(5.5, 7.0).max(3.0 + 2.0 * radius) * 10.0).ceil() / 10.0;
            let w = ((2.0 * radius + 0.8).max(rng.range(3.5, 5.0)) * 10.0).ceil() / 10.0;
            let goal = [round_to(l - 0.4 - radius, 2), 0.0];
            let start = [1.0, round_to(rng.range(-0.6, 0.6), 2)];
            b.param("room_m", inner);
            b.param("wall_height_m", height);
            let o = inner / 2.0 + t / 2.0;
            for (name, c, size) in [
                ("front", [-o, 0.0], [t, inner + 2.0 * t]),
                ("back", [o, 0.0], [t, inner + 2.0 * t]),
                ("left", [0.0, o], [inner + 2.0 * t, t]),
                ("right", [0.0, -o], [inner + 2.0 * t, t]),
            ] {
                b.add_box(
                    format!("{name} wall around the goal"),
                    sub(goal, turn, c),
                    size,
                    height,
                    turn,
                );
            }
            let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
            let description = format!(
                "impossible: the goal is walled in by {height:.2} m walls ({inner:.2} m room)"
            );
            let (s, g) = (b.pose(start, start_yaw), b.pose(goal, goal_yaw));
            Ok(b.finish(description, map, s, g, Outcome::NoPath, 0, 0.0))
        }
        _ => {
            let l = round_to(rng.range(6.0, 8.0), 1);
            let w = round_to(rng.range(3.5, 5.0), 1);
            let wall_yaw = round_to(rng.range(-WALL_YAW_DEG, WALL_YAW_DEG), 1);
            let (thickness, height, door) = if variant == 1 {
                (round_to(rng.range(0.15, 0.8), 2), HIGH_WALL_HEIGHT_M.draw(rng, 3), 0.0)
            } else {
                (
                    round_to(rng.range(0.1, 0.3), 2),
                    WALL_HEIGHT_M.draw(rng, 2),
                    TIGHT_DOOR_WIDTH_M.draw(rng, 2),
                )
            };
            let origin =
                [l / 2.0, if door > 0.0 { round_to(rng.range(-0.5, 0.5), 2) } else { 0.0 }];
            let start = [1.0, round_to(rng.range(-0.5, 0.5), 2)];
            let goal = [l - 1.0, round_to(rng.range(-0.5, 0.5), 2)];
            for p in [start, goal] {
                let x = in_sub(origin, wall_yaw, p)[0].abs() - thickness / 2.0;
                reject_unless(x >= 0.8, || format!("a pose only {x:.2} m from the wall"))?;
            }
            b.param("wall_yaw_deg", wall_yaw);
            b.param("wall_height_m", height);
            b.param("wall_thickness_m", thickness);
            b.param("door_m", door);
            let map = b.map(&rect(0.0, l, -w / 2.0, w / 2.0), 0.0);
            let corners = b.local_corners(&map);
            wall_across(
                &mut b,
                &corners,
                origin,
                wall_yaw,
                thickness,
                height,
                door,
                "wall across the map",
            );
            let description = if door > 0.0 {
                format!(
                    "impossible: a {door:.2} m doorway, narrower than the robot, in a {height:.2} m wall at {wall_yaw:.1}°"
                )
            } else {
                format!(
                    "impossible: a {height:.3} m wall, {thickness:.2} m thick, across the map at {wall_yaw:.1}° (steps reach 0.3 m)"
                )
            };
            let (s, g) = (b.pose(start, start_yaw), b.pose(goal, goal_yaw));
            Ok(b.finish(description, map, s, g, Outcome::NoPath, 0, 0.0))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SEEDS: std::ops::Range<u64> = 1..51;

    fn case(class: Class, seed: u64) -> GeneratedCase {
        generate(class, seed).unwrap_or_else(|e| panic!("{e}"))
    }

    fn stairs_of(c: &GeneratedCase) -> Vec<(u32, f64, f64, f64, f64)> {
        c.terrain
            .iter()
            .filter_map(|p| match p.primitive {
                Primitive::Stairs {
                    steps, step_depth, step_height, width, landing_depth, ..
                } => Some((steps, step_depth, step_height, width, landing_depth)),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn class_names_round_trip_and_cases_cycle() {
        for (k, c) in Class::ALL.iter().enumerate() {
            assert_eq!(Class::from_name(c.name()), Some(*c));
            assert_eq!(c.name().parse::<Class>(), Ok(*c));
            assert_eq!(Class::of_case(k as u64), *c);
            assert_eq!(Class::of_case(k as u64 + 8), *c);
        }
        assert!("stair".parse::<Class>().is_err());
    }

    #[test]
    fn same_seed_same_text_other_seed_other_text() {
        for class in Class::ALL {
            let a = case(class, 7).to_toml();
            assert_eq!(a, case(class, 7).to_toml(), "{class}");
            assert_ne!(a, case(class, 8).to_toml(), "{class}");
        }
    }

    #[test]
    fn draws_continue_one_stream() {
        let mut d = Draws::new(Class::Clutter, 3);
        let first = d.next_case().unwrap();
        let second = d.next_case().unwrap();
        assert_ne!(first.to_toml(), second.to_toml());
        assert!(second.draw > first.draw);
        let mut again = Draws::new(Class::Clutter, 3);
        assert_eq!(again.next_case().unwrap(), first);
        assert_eq!(again.next_case().unwrap(), second);
    }

    #[test]
    fn every_class_parses_with_its_class_name_and_small_map() {
        for class in Class::ALL {
            for seed in SEEDS {
                let c = case(class, seed);
                let s = c.scenario(Path::new("generated")).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(s.class.as_deref(), Some(class.name()));
                assert_eq!(s.name, format!("{class}_{seed:06}"));
                assert_eq!(c.file_name(), format!("{class}_{seed:06}.toml"));
                assert!(!s.description.is_empty());
                let (a, b) = (s.map.x_max - s.map.x_min, s.map.y_max - s.map.y_min);
                assert!(a.max(b) <= 10.0 + 1e-9 && a.min(b) <= 6.0 + 1e-9, "{}: {a} x {b}", s.name);
                assert_eq!(s.expect.outcome, c.outcome);
                assert!(s.expect.timeout_s >= 60.0);
                if c.outcome == Outcome::Reach {
                    assert_eq!(s.expect.goal_tolerance_m, 0.1);
                    assert_eq!(s.expect.goal_tolerance_deg, 10.0);
                    assert_eq!(s.expect.min_stability_margin_m, 0.02);
                }
                assert!(s.map.contains(s.start.x, s.start.y) && s.map.contains(s.goal.x, s.goal.y));
                // Stairs ask for the models that climb treads shorter than the robot; the
                // other classes name none and get the defaults for their terrain.
                let (step, foot) = class.models().unwrap_or_else(|| {
                    let (foot, step) = crate::scenario::default_models(&s.terrain);
                    (step, foot)
                });
                assert_eq!((s.params.step_model, s.params.foot_model), (step, foot), "{}", s.name);
                assert_eq!(class == Class::Stairs, step == StepModel::Stairs);
            }
        }
    }

    #[test]
    fn only_impossible_cases_expect_no_path() {
        for class in Class::ALL {
            for seed in SEEDS {
                let c = case(class, seed);
                let want =
                    if class == Class::Impossible { Outcome::NoPath } else { Outcome::Reach };
                assert_eq!(c.outcome, want, "{}", c.name);
            }
        }
    }

    #[test]
    fn headings_are_off_the_lattice() {
        for seed in SEEDS {
            let c = case(Class::Headings, seed);
            for yaw in [c.start.yaw_deg, c.goal.yaw_deg] {
                assert!((-180.0..180.0).contains(&yaw), "{yaw}");
                assert!(off_lattice_deg(yaw) >= MIN_OFF_LATTICE_DEG - 1e-9, "{}: {yaw}", c.name);
            }
        }
        assert_eq!(off_lattice_deg(11.25), 0.0);
        assert!((off_lattice_deg(-3.0) - 2.625).abs() < 1e-12);
    }

    #[test]
    fn stairs_parameters_stay_in_their_ranges() {
        let (mut up, mut walls, mut mid) = (0, 0, 0);
        for seed in SEEDS {
            let c = case(Class::Stairs, seed);
            let p = &c.parameters;
            let steps = p["steps"] as u32;
            assert!((STAIR_STEPS[0]..=STAIR_STEPS[1]).contains(&steps));
            assert!(STAIR_RISE_M.contains(p["rise_m"]), "{}", c.name);
            assert!(STAIR_TREAD_M.contains(p["tread_m"]), "{}", c.name);
            assert!(STAIR_WIDTH_M.contains(p["width_m"]));
            assert!(STAIR_LANDING_M.contains(p["top_landing_m"]));
            let flights = stairs_of(&c);
            let (n, tread, rise, width, landing) = *flights.last().unwrap();
            assert_eq!(n, steps);
            assert_eq!(
                (tread, rise, width, landing),
                (p["tread_m"], p["rise_m"], p["width_m"], p["top_landing_m"])
            );
            if p["mid_landing_m"] > 0.0 {
                mid += 1;
                assert!(STAIR_MID_LANDING_M.contains(p["mid_landing_m"]));
                assert_eq!(flights.len(), 2);
                assert!(steps >= 4);
            }
            up += p["up"] as u32;
            walls += p["walls"] as u32;
            // The top of the flight: the goal going up, the start going down.
            let s = c.scenario(Path::new("")).unwrap();
            let top = f64::from(steps) * rise;
            let (hi, lo) = if p["up"] == 1.0 { (s.goal, s.start) } else { (s.start, s.goal) };
            assert!((s.terrain_height(hi.x, hi.y) - top).abs() < 1e-9, "{}", c.name);
            assert_eq!(s.terrain_height(lo.x, lo.y), 0.0, "{}", c.name);
            assert!(
                c.description.starts_with("stairs up:")
                    || c.description.starts_with("stairs down:")
            );
        }
        assert!(up > 10 && up < 40 && walls > 10 && walls < 40 && mid > 3, "{up} {walls} {mid}");
    }

    #[test]
    fn two_flights_make_one_staircase() {
        let c = (1..200)
            .map(|s| case(Class::Stairs, s))
            .find(|c| c.parameters["mid_landing_m"] > 0.0 && c.parameters["yaw_deg"] != 0.0)
            .unwrap();
        let s = c.scenario(Path::new("")).unwrap();
        let p = &c.parameters;
        let (k1, tread, rise, mid) =
            (p["mid_landing_after"], p["tread_m"], p["rise_m"], p["mid_landing_m"]);
        let Primitive::Stairs { start, yaw_deg, .. } = c.terrain[0].primitive else { panic!() };
        let at = |x: f64| {
            let w = sub(start, yaw_deg, [x, 0.0]);
            s.terrain_height(w[0], w[1])
        };
        for k in 1..=(p["steps"] as u32) {
            let k = f64::from(k);
            let x = if k <= k1 { (k - 0.5) * tread } else { (k - 0.5) * tread + mid };
            assert!((at(x) - k * rise).abs() < 1e-9, "{}: step {k}", c.name);
        }
        assert!((at(k1 * tread + mid / 2.0) - k1 * rise).abs() < 1e-9, "mid landing");
    }

    /// Heights over a 5 cm grid of the map, with each point's coordinate along the
    /// normal of the edges (world angle `heading + edge_yaw`) through the world origin.
    fn over_map(s: &Scenario, normal_deg: f64) -> Vec<(f64, f64)> {
        let (sn, cs) = normal_deg.to_radians().sin_cos();
        let m = s.map;
        let (nx, ny) = (((m.x_max - m.x_min) / 0.05) as i32, ((m.y_max - m.y_min) / 0.05) as i32);
        let mut v = Vec::new();
        for i in 0..=nx {
            for j in 0..=ny {
                let (x, y) = (m.x_min + f64::from(i) * 0.05, m.y_min + f64::from(j) * 0.05);
                v.push((x * cs + y * sn, s.terrain_height(x, y)));
            }
        }
        v
    }

    #[test]
    fn edge_classes_stay_in_their_ranges_and_block_the_whole_map() {
        for seed in SEEDS {
            let c = case(Class::StepDown, seed);
            let s = c.scenario(Path::new("")).unwrap();
            let p = &c.parameters;
            let h = p["height_m"];
            assert!(STEP_DOWN_HEIGHT_M.contains(h));
            assert!(p["edge_yaw_deg"].abs() <= EDGE_YAW_DEG);
            assert_eq!(s.terrain_height(s.start.x, s.start.y), h, "{}", c.name);
            assert_eq!(s.terrain_height(s.goal.x, s.goal.y), 0.0, "{}", c.name);
            // The platform covers the whole map behind its edge and nothing beyond it (the
            // corridor walls, 0.8 m, aside): no way around.
            for (n, z) in over_map(&s, p["heading_deg"] + p["edge_yaw_deg"]) {
                if z != 0.8 && n.abs() > 0.01 {
                    assert_eq!(z, if n < 0.0 { h } else { 0.0 }, "{}: at {n:.3}", c.name);
                }
            }

            let c = case(Class::UpAndOver, seed);
            let s = c.scenario(Path::new("")).unwrap();
            let p = &c.parameters;
            let (h, d) = (p["height_m"], p["depth_m"]);
            assert!(UP_AND_OVER_HEIGHT_M.contains(h) && UP_AND_OVER_DEPTH_M.contains(d));
            assert!(p["edge_yaw_deg"].abs() <= EDGE_YAW_DEG);
            assert_eq!(s.terrain_height(s.start.x, s.start.y), 0.0);
            assert_eq!(s.terrain_height(s.goal.x, s.goal.y), 0.0);
            for (n, z) in over_map(&s, p["heading_deg"] + p["edge_yaw_deg"]) {
                if z != 0.8 && n.abs() > 0.01 && (n - d).abs() > 0.01 {
                    assert_eq!(z, if n > 0.0 && n < d { h } else { 0.0 }, "{}: at {n:.3}", c.name);
                }
            }
        }
    }

    #[test]
    fn clutter_narrow_mixed_and_impossible_stay_in_their_ranges() {
        for seed in SEEDS {
            let c = case(Class::Clutter, seed);
            for p in &c.terrain {
                let h = p.primitive.max_height();
                assert!(
                    CLUTTER_HEIGHT_M.contains(h) || BUMP_HEIGHT_M.contains(h),
                    "{}: {} at {h}",
                    c.name,
                    p.note
                );
                assert!(h <= 0.5);
            }
            assert!(c.parameters["obstacles"] >= 1.0, "{}", c.name);

            let c = case(Class::Narrow, seed);
            assert!(DOOR_WIDTH_M.contains(c.parameters["door_m"]));
            assert!(c.parameters["wall_yaw_deg"].abs() <= WALL_YAW_DEG);
            assert!(WALL_HEIGHT_M.contains(c.parameters["wall_height_m"]));

            let c = case(Class::Mixed, seed);
            let drop = c.parameters["step_down_m"];
            assert!(drop > 0.05 && drop <= 0.3 + 1e-9, "{}: {drop}", c.name);
            let s = c.scenario(Path::new("")).unwrap();
            assert!((s.goal.x - s.start.x).hypot(s.goal.y - s.start.y) >= 5.5, "{}", c.name);
            let long = (s.map.x_max - s.map.x_min).max(s.map.y_max - s.map.y_min);
            assert!(long >= 7.5, "{}: {long}", c.name);

            let c = case(Class::Impossible, seed);
            let p = &c.parameters;
            match p["variant"] as u32 {
                0 => assert!(ENCLOSURE_HEIGHT_M.contains(p["wall_height_m"])),
                1 => {
                    assert!(HIGH_WALL_HEIGHT_M.contains(p["wall_height_m"]));
                    assert!(p["wall_height_m"] > 0.35);
                    // One box whose length reaches 1 m past every map corner.
                    let Primitive::Box { center, size, yaw_deg, .. } = c.terrain[0].primitive
                    else {
                        panic!("{}: {:?}", c.name, c.terrain[0])
                    };
                    let m = c.map;
                    for q in [
                        [m.x_min, m.y_min],
                        [m.x_max, m.y_min],
                        [m.x_min, m.y_max],
                        [m.x_max, m.y_max],
                    ] {
                        let along = in_sub(center, yaw_deg, q)[1].abs();
                        assert!(along <= size[1] / 2.0 - 0.999, "{}", c.name);
                    }
                }
                _ => {
                    assert!(TIGHT_DOOR_WIDTH_M.contains(p["door_m"]));
                    assert!(p["door_m"] < 0.6);
                }
            }
        }
    }

    #[test]
    fn walled_in_goal_is_enclosed_on_every_side() {
        let c = (1..200)
            .map(|s| case(Class::Impossible, s))
            .find(|c| c.parameters["variant"] == 0.0)
            .unwrap();
        let s = c.scenario(Path::new("")).unwrap();
        let h = c.parameters["wall_height_m"];
        // Every ray from the goal meets a wall before 2 m.
        for k in 0..72 {
            let a = f64::from(k) * 5f64.to_radians();
            let hit = (1..=80).any(|i| {
                let r = f64::from(i) * 0.025;
                s.terrain_height(s.goal.x + r * a.cos(), s.goal.y + r * a.sin()) == h
            });
            assert!(hit, "{}: ray {k}", c.name);
        }
    }

    #[test]
    fn written_numbers_are_toml_floats() {
        assert_eq!(num(2.0), "2.0");
        assert_eq!(num(-0.0), "0.0");
        assert_eq!(num(0.17), "0.17");
        assert_eq!(deg(180.0), -180.0);
        assert_eq!(deg(-180.04), -180.0);
        assert_eq!(deg(359.96), 0.0);
        assert_eq!(quote("a \"b\" \\ c"), r#""a \"b\" \\ c""#);
    }
}
