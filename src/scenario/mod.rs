//! Scenario files: terrain, map extent, start and goal, parameter overrides, expectations.
//!
//! A scenario is a TOML file (format documented in `scenarios/README.md`). Loading parses
//! it strictly (unknown keys are errors) and validates every number, so a broken file
//! fails here with its path and the offending field, never later as a panic or a silently
//! wrong plan. The terrain primitives feed both the MuJoCo world (`sim::world`) and the
//! rasterised height map (`terrain`).
//!
//! **Models a file does not name.** `[params]` may name `foot_model` and `step_model`;
//! the models it leaves out ([`NamedModels`]) are chosen when the planner's world is
//! prepared, from the height map and the robot alone (`planner::world::terrain_models`):
//! a flight of steps gets the models that climb it whether it is written as a `stairs`
//! primitive, as stacked boxes or seen by a laser. Until then [`Scenario::params`] holds
//! [`Params`]' defaults (the paper's) for them.

mod field;
pub mod generate;
pub mod terrain;

use crate::geometry::Pose2;
use crate::params::{FootModel, Params, StepModel};
use field::{FieldError, finite, non_negative, positive};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
pub use terrain::Primitive;

/// Why a scenario could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not match the format (wrong type, unknown key).
    #[error("malformed scenario {path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message, naming the key and line.
        message: String,
    },
    /// A value is out of range.
    #[error("invalid scenario {path}: field `{field}`: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Dotted path of the field, e.g. `terrain[2].size`.
        field: String,
        /// What is wrong with it.
        reason: String,
    },
}

/// Rectangular extent of the map, m.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapExtent {
    /// Lower x bound.
    pub x_min: f64,
    /// Upper x bound.
    pub x_max: f64,
    /// Lower y bound.
    pub y_min: f64,
    /// Upper y bound.
    pub y_max: f64,
}

impl MapExtent {
    /// Whether (x, y) lies inside the extent.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x_min && x <= self.x_max && y >= self.y_min && y <= self.y_max
    }
}

/// A pose as written in a scenario: position in metres, yaw in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// Yaw, degrees, counter-clockwise from +x.
    #[serde(default)]
    pub yaw_deg: f64,
}

impl PoseSpec {
    /// As a planar pose (yaw in radians).
    pub fn pose(&self) -> Pose2 {
        Pose2::new(self.x, self.y, self.yaw_deg.to_radians())
    }
}

/// Whether a scenario's plan must, may or must not contain steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stepping {
    /// No expectation.
    #[default]
    Any,
    /// The plan must contain at least one step.
    Required,
    /// The plan must drive only.
    Forbidden,
}

/// What the right answer to a scenario is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The robot must reach the goal within the tolerances.
    #[default]
    Reach,
    /// The course is impossible: the planner must answer "no path" (and nothing may be
    /// executed).
    NoPath,
}

/// What a closed-loop run of the scenario must show to pass.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Expectations {
    /// The right answer: reach the goal, or a clean "no path".
    pub outcome: Outcome,
    /// Position tolerance at the goal, m.
    pub goal_tolerance_m: f64,
    /// Heading tolerance at the goal, degrees.
    pub goal_tolerance_deg: f64,
    /// Whether the plan must or must not step.
    pub stepping: Stepping,
    /// Minimum static stability margin measured during the run, m.
    pub min_stability_margin_m: f64,
    /// Longest total time the measured CoM may lie outside the support polygon of the
    /// supporting wheels (a static-stability violation, see `monitor`), s.
    pub max_static_violation_s: f64,
    /// Simulated-time budget of a run, s.
    pub timeout_s: f64,
}

impl Default for Expectations {
    fn default() -> Self {
        Self {
            outcome: Outcome::Reach,
            goal_tolerance_m: 0.1,
            goal_tolerance_deg: 10.0,
            stepping: Stepping::Any,
            min_stability_margin_m: 0.0,
            max_static_violation_s: DEFAULT_MAX_STATIC_VIOLATION_S,
            timeout_s: 120.0,
        }
    }
}

/// Default bound on the total duration of static-stability violations in a run, s: a
/// few control ticks of a wheel bouncing on a bump edge, never a lean that lasts.
pub const DEFAULT_MAX_STATIC_VIOLATION_S: f64 = 0.1;

/// Largest height map a scenario may ask for, in cells (at the scenario's grid
/// resolution, margin included): 4 M cells is a 50 m × 50 m map at 2.5 cm, about
/// 200 MB of planner memory. Larger maps are refused with the cell count, not left to
/// abort in an allocation.
pub const MAX_MAP_CELLS: f64 = 4.0e6;

/// The file format, exactly as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
    name: Option<String>,
    #[serde(default)]
    description: String,
    class: Option<String>,
    map: MapExtent,
    start: PoseSpec,
    goal: PoseSpec,
    #[serde(default)]
    terrain: Vec<Primitive>,
    #[serde(default)]
    params: Params,
    #[serde(default)]
    expect: Expectations,
}

/// The model keys of a file's `[params]` (the rest of the file is [`ScenarioFile`]'s).
#[derive(Debug, Default, Deserialize)]
struct ModelKeys {
    #[serde(default)]
    params: NamedModelKeys,
}

/// The model keys of `[params]`, present or not.
#[derive(Debug, Default, Deserialize)]
struct NamedModelKeys {
    foot_model: Option<toml::Value>,
    step_model: Option<toml::Value>,
}

/// Which of the planner's models a scenario file names in `[params]`; the planner
/// chooses the others from the terrain's height map (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct NamedModels {
    /// `foot_model` is named.
    pub foot: bool,
    /// `step_model` is named.
    pub step: bool,
}

/// A loaded, validated scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scenario {
    /// Name (the file stem unless given).
    pub name: String,
    /// Where it was loaded from.
    pub path: PathBuf,
    /// One-line description.
    pub description: String,
    /// The class of course (`stairs`, `clutter`, ...; see `momaro generate`), for the
    /// per-class totals of `momaro check`; `None` for hand-written scenarios.
    pub class: Option<String>,
    /// Map extent.
    pub map: MapExtent,
    /// Start pose.
    pub start: Pose2,
    /// Goal pose.
    pub goal: Pose2,
    /// Terrain primitives on the ground plane.
    pub terrain: Vec<Primitive>,
    /// The paper's parameters with this scenario's overrides.
    pub params: Params,
    /// Which models `params` holds because the file names them (set them with
    /// [`Self::set_foot_model`] and [`Self::set_step_model`]: a model written into
    /// `params` alone is replaced by the terrain's).
    pub named_models: NamedModels,
    /// What a run must show.
    pub expect: Expectations,
}

impl Scenario {
    /// Plans with foot model `model`, as if the file named it (the planner then does not
    /// choose one from the terrain).
    pub fn set_foot_model(&mut self, model: FootModel) {
        self.params.foot_model = model;
        self.named_models.foot = true;
    }

    /// Plans with step model `model`, as if the file named it.
    pub fn set_step_model(&mut self, model: StepModel) {
        self.params.step_model = model;
        self.named_models.step = true;
    }

    /// Reads and validates a scenario file.
    ///
    /// # Errors
    /// [`ScenarioError`] naming the file and, for bad values, the field.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| ScenarioError::Io { path: path.to_owned(), source })?;
        Self::parse(&text, path)
    }

    /// Parses and validates scenario text; `path` is used for the name and in errors.
    ///
    /// # Errors
    /// [`ScenarioError::Parse`] or [`ScenarioError::Invalid`].
    pub fn parse(text: &str, path: &Path) -> Result<Self, ScenarioError> {
        let file: ScenarioFile = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            path: path.to_owned(),
            message: e.to_string().trim_end().replace('\n', " "),
        })?;
        let invalid = |field: &str, reason: String| ScenarioError::Invalid {
            path: path.to_owned(),
            field: field.to_owned(),
            reason,
        };
        validate(&file).map_err(|(field, reason)| invalid(&field, reason))?;
        // The same text parsed above, so this cannot fail where that did not.
        let keys: ModelKeys = toml::from_str(text).unwrap_or_default();
        let named_models = NamedModels {
            foot: keys.params.foot_model.is_some(),
            step: keys.params.step_model.is_some(),
        };
        let name = file.name.clone().unwrap_or_else(|| {
            path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
        });
        Ok(Scenario {
            name,
            path: path.to_owned(),
            description: file.description,
            class: file.class,
            map: file.map,
            start: file.start.pose(),
            goal: file.goal.pose(),
            terrain: file.terrain,
            params: file.params,
            named_models,
            expect: file.expect,
        })
    }

    /// Terrain height at (x, y): ground plane and primitives.
    pub fn terrain_height(&self, x: f64, y: f64) -> f64 {
        terrain::terrain_height(&self.terrain, x, y)
    }
}

fn validate(f: &ScenarioFile) -> Result<(), FieldError> {
    let m = &f.map;
    for (name, v) in [
        ("map.x_min", m.x_min),
        ("map.x_max", m.x_max),
        ("map.y_min", m.y_min),
        ("map.y_max", m.y_max),
    ] {
        finite(name, v)?;
    }
    if m.x_max <= m.x_min {
        return Err((
            "map.x_max".into(),
            format!("{} must exceed map.x_min = {}", m.x_max, m.x_min),
        ));
    }
    if m.y_max <= m.y_min {
        return Err((
            "map.y_max".into(),
            format!("{} must exceed map.y_min = {}", m.y_max, m.y_min),
        ));
    }
    // The height map covers the extent plus r_N on every side (`terrain::rasterise`).
    let res = f.params.grid_resolution_m;
    if res.is_finite() && res > 0.0 {
        let pad = 2.0 * f.params.r_n_m;
        let cells =
            ((m.x_max - m.x_min + pad) / res).ceil() * ((m.y_max - m.y_min + pad) / res).ceil();
        if cells.is_nan() || cells > MAX_MAP_CELLS {
            return Err((
                "map".into(),
                format!(
                    "{:.3e} cells of {res} m, more than the limit of {MAX_MAP_CELLS:.0} (a 50 m x 50 m map at 2.5 cm)",
                    cells
                ),
            ));
        }
    }
    for (name, p) in [("start", &f.start), ("goal", &f.goal)] {
        finite(&format!("{name}.x"), p.x)?;
        finite(&format!("{name}.y"), p.y)?;
        finite(&format!("{name}.yaw_deg"), p.yaw_deg)?;
        if !m.contains(p.x, p.y) {
            return Err((
                name.into(),
                format!(
                    "({}, {}) lies outside the map [{}, {}] x [{}, {}]",
                    p.x, p.y, m.x_min, m.x_max, m.y_min, m.y_max
                ),
            ));
        }
    }
    for (i, prim) in f.terrain.iter().enumerate() {
        prim.validate(&format!("terrain[{i}]"))?;
    }
    f.params
        .validate()
        .map_err(|e| (format!("params.{}", e.name), format!("{} {}", e.value, e.reason)))?;
    // Inside an obstacle: under the base (a disc of the base-circle radius) the terrain
    // rises above its lowest point by more than the clearance under the base while driving.
    // Standing on a platform or a landing is fine; a pole under the base is fine if low.
    for (name, p) in [("start", &f.start), ("goal", &f.goal)] {
        let r = f.params.base_circle_radius_m;
        let mut samples = vec![(p.x, p.y)];
        for k in 0..16 {
            let a = f64::from(k) * std::f64::consts::TAU / 16.0;
            for rr in [r / 2.0, r] {
                samples.push((p.x + rr * a.cos(), p.y + rr * a.sin()));
            }
        }
        let heights: Vec<f64> =
            samples.iter().map(|&(x, y)| terrain::terrain_height(&f.terrain, x, y)).collect();
        let lo = heights.iter().copied().fold(f64::INFINITY, f64::min);
        let (k, hi) = heights
            .iter()
            .copied()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |a, (k, h)| if h > a.1 { (k, h) } else { a });
        if hi - lo > f.params.driving_leg_height_m {
            let (x, y) = samples[k];
            let culprit = f
                .terrain
                .iter()
                .position(|prim| prim.surface_height(x, y) == Some(hi))
                .map_or(String::new(), |i| format!(" (terrain[{i}], {})", f.terrain[i].kind()));
            return Err((
                name.into(),
                format!(
                    "({}, {}): terrain{culprit} rises {:.2} m under the base, more than its {:.2} m clearance: the robot would be inside an obstacle",
                    p.x,
                    p.y,
                    hi - lo,
                    f.params.driving_leg_height_m
                ),
            ));
        }
    }
    let e = &f.expect;
    non_negative("expect.goal_tolerance_m", e.goal_tolerance_m)?;
    non_negative("expect.goal_tolerance_deg", e.goal_tolerance_deg)?;
    finite("expect.min_stability_margin_m", e.min_stability_margin_m)?;
    non_negative("expect.max_static_violation_s", e.max_static_violation_s)?;
    if let Some(c) = &f.class
        && (c.is_empty() || !c.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '_'))
    {
        return Err((
            "class".into(),
            format!("`{c}` must be a non-empty word of letters, digits and _"),
        ));
    }
    positive("expect.timeout_s", e.timeout_s)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
        [map]
        x_min = -1.0
        x_max = 5.0
        y_min = -2.0
        y_max = 2.0
        [start]
        x = 0.0
        y = 0.0
        [goal]
        x = 4.0
        y = 0.5
        yaw_deg = 90
        [[terrain]]
        kind = "box"
        center = [2.0, 1.5]
        size = [0.5, 0.5]
        height = 0.2
        [params]
        k12 = 1.5
    "#;

    fn parse(text: &str) -> Result<Scenario, ScenarioError> {
        Scenario::parse(text, Path::new("scenarios/test.toml"))
    }

    fn field_of(text: &str) -> String {
        match parse(text) {
            Err(ScenarioError::Invalid { field, .. }) => field,
            other => panic!("expected an invalid-field error, got {other:?}"),
        }
    }

    #[test]
    fn good_file_parses_with_overrides_and_defaults() {
        let s = parse(GOOD).unwrap();
        assert_eq!(s.name, "test");
        assert_eq!(s.params.k12, 1.5);
        assert_eq!(s.params.k1, 100.0);
        assert!((s.goal.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(s.expect.outcome, Outcome::Reach);
        assert_eq!(s.class, None);
        assert_eq!(s.terrain_height(2.0, 1.5), 0.2);
    }

    #[test]
    fn unknown_key_names_the_key_and_file() {
        let e = parse(&GOOD.replace("[params]", "[params]\nk99 = 1")).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("k99") && msg.contains("scenarios/test.toml"), "{msg}");
    }

    #[test]
    fn foot_model_parses_and_a_bad_one_names_the_choices() {
        assert_eq!(parse(GOOD).unwrap().params.foot_model, FootModel::Paper);
        let wp = GOOD.replace("[params]", "[params]\nfoot_model = \"wheel_pair\"");
        assert_eq!(parse(&wp).unwrap().params.foot_model, FootModel::WheelPair);
        let e = parse(&GOOD.replace("[params]", "[params]\nfoot_model = \"wheels\"")).unwrap_err();
        assert!(matches!(e, ScenarioError::Parse { .. }));
        let msg = e.to_string();
        assert!(
            msg.contains("foot_model") && msg.contains("`paper`") && msg.contains("`wheel_pair`"),
            "{msg}"
        );
    }

    #[test]
    fn a_file_s_named_models_are_kept_and_the_others_left_to_the_terrain() {
        // Unnamed models keep `Params`' (the paper's) until the planner reads the height
        // map; a stairs primitive does not choose them.
        let flight = |params: &str| {
            let stairs = format!(
                "[[terrain]]\nkind = \"stairs\"\nstart = [1.0, -1.4]\nwidth = 0.8\n\
                 steps = 6\nstep_depth = 0.29\nstep_height = 0.17\n[params]\n{params}"
            );
            let s = parse(&GOOD.replace("[params]", &stairs)).unwrap();
            (s.params.foot_model, s.params.step_model, s.named_models)
        };
        let named = |foot, step| NamedModels { foot, step };
        let (paper_foot, paper) = (FootModel::Paper, StepModel::Paper);
        assert_eq!(flight(""), (paper_foot, paper, named(false, false)));
        assert_eq!(
            flight("step_model = \"stairs\""),
            (paper_foot, StepModel::Stairs, named(false, true))
        );
        assert_eq!(
            flight("foot_model = \"wheel_pair\"\nstep_model = \"paper\""),
            (FootModel::WheelPair, paper, named(true, true))
        );
        let bare = GOOD.split("[params]").next().unwrap();
        assert_eq!(parse(bare).unwrap().named_models, named(false, false));
    }

    #[test]
    fn wrong_type_is_a_parse_error_naming_the_key() {
        let e = parse(&GOOD.replace("x = 4.0", "x = \"far\"")).unwrap_err();
        assert!(matches!(e, ScenarioError::Parse { .. }));
        assert!(e.to_string().contains("x"), "{e}");
    }

    #[test]
    fn negative_size_names_the_field() {
        assert_eq!(
            field_of(&GOOD.replace("size = [0.5, 0.5]", "size = [-0.5, 0.5]")),
            "terrain[0].size"
        );
    }

    #[test]
    fn goal_outside_map_is_rejected() {
        assert_eq!(field_of(&GOOD.replace("x = 4.0", "x = 40.0")), "goal");
    }

    #[test]
    fn nan_is_rejected() {
        assert_eq!(field_of(&GOOD.replace("y = 0.5", "y = nan")), "goal.y");
        assert_eq!(field_of(&GOOD.replace("k12 = 1.5", "k12 = nan")), "params.k12");
    }

    #[test]
    fn start_inside_an_obstacle_is_rejected() {
        let text = GOOD
            .replace("center = [2.0, 1.5]", "center = [0.0, 0.0]")
            .replace("height = 0.2", "height = 0.5");
        assert_eq!(field_of(&text), "start");
    }

    #[test]
    fn standing_on_a_platform_is_not_inside_it() {
        let text = GOOD
            .replace("center = [2.0, 1.5]", "center = [0.0, 0.0]")
            .replace("size = [0.5, 0.5]", "size = [3.0, 3.0]")
            .replace("height = 0.2", "height = 0.5");
        parse(&text).unwrap();
    }

    #[test]
    fn a_map_too_large_to_allocate_names_map_and_its_cells() {
        // 1 km x 1 km at 2.5 cm: 1.6e9 cells.
        let text =
            GOOD.replace("x_max = 5.0", "x_max = 999.0").replace("y_max = 2.0", "y_max = 998.0");
        match parse(&text) {
            Err(ScenarioError::Invalid { field, reason, .. }) => {
                assert_eq!(field, "map");
                assert!(reason.contains("1.6") && reason.contains("4000000"), "{reason}");
            }
            other => panic!("expected an invalid map, got {other:?}"),
        }
        // 49 m x 49 m is fine.
        let text =
            GOOD.replace("x_max = 5.0", "x_max = 48.0").replace("y_max = 2.0", "y_max = 47.0");
        parse(&text).unwrap();
    }

    #[test]
    fn outcome_and_class_parse_and_bad_values_name_their_field() {
        let s = parse(&format!("class = \"stairs\"\n{GOOD}\n[expect]\noutcome = \"no_path\"\n"))
            .unwrap();
        assert_eq!(s.expect.outcome, Outcome::NoPath);
        assert_eq!(s.class.as_deref(), Some("stairs"));
        let e = parse(&format!("{GOOD}\n[expect]\noutcome = \"maybe\"\n")).unwrap_err();
        assert!(
            matches!(e, ScenarioError::Parse { .. }) && e.to_string().contains("outcome"),
            "{e}"
        );
        assert_eq!(field_of(&format!("class = \"a b\"\n{GOOD}")), "class");
        assert_eq!(
            field_of(&format!("{GOOD}\n[expect]\nmax_static_violation_s = -1\n")),
            "expect.max_static_violation_s"
        );
    }

    #[test]
    fn missing_file_is_an_io_error_naming_it() {
        let e = Scenario::load(Path::new("/nonexistent/x.toml")).unwrap_err();
        assert!(matches!(e, ScenarioError::Io { .. }));
        assert!(e.to_string().contains("/nonexistent/x.toml"));
    }
}
