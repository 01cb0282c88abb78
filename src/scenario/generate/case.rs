//! A generated case and its scenario file.
//!
//! The file is written by serde (`toml`) from the scenario format's own types, the same
//! that read it ([`MapExtent`], [`PoseSpec`], [`Primitive`], [`Expectations`]), so what
//! is written is what loads: no number or key is spelt out by hand. Only comments are
//! added to serde's text: a header naming the command and the drawn parameters, and above
//! each `[[terrain]]` table what the primitive is for.

use super::{Class, GenerateError};
use crate::params::{FootModel, StepModel};
use crate::scenario::{Expectations, MapExtent, Outcome, PoseSpec, Primitive, Scenario};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

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

/// A case's scenario file, in the format's order (values before tables).
#[derive(Serialize)]
struct CaseFile<'a> {
    class: Class,
    name: &'a str,
    description: &'a str,
    map: MapExtent,
    start: PoseSpec,
    goal: PoseSpec,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    terrain: Vec<&'a Primitive>,
    #[serde(skip_serializing_if = "Option::is_none")]
    params: Option<NamedModels>,
    expect: Expectations,
}

/// The models a class's files name in `[params]` (the other parameters keep
/// [`crate::params::Params`]' defaults and are not written).
#[derive(Serialize)]
struct NamedModels {
    step_model: StepModel,
    foot_model: FootModel,
}

impl GeneratedCase {
    /// This case with every flight of stairs written as stacked boxes, a box per step
    /// (`Primitive::as_boxes`): the same heights cell for cell, no `stairs` label. The
    /// file name, class and description stay, so a labelled course and its box version
    /// pair by name.
    #[must_use]
    pub fn with_stairs_as_boxes(mut self) -> Self {
        self.terrain = self
            .terrain
            .into_iter()
            .flat_map(|p| {
                let boxes = p.primitive.as_boxes();
                let n = boxes.len();
                boxes.into_iter().enumerate().map(move |(k, primitive)| Placed {
                    note: if n > 1 {
                        format!("{}, step {} as a box", p.note, k + 1)
                    } else {
                        p.note.clone()
                    },
                    primitive,
                })
            })
            .collect();
        self
    }

    /// The file name: `{class}_{seed:06}.toml`.
    pub fn file_name(&self) -> String {
        format!("{}.toml", self.name)
    }

    /// What a run of the case must show: the outcome in the time budget and, for a
    /// course to reach, the goal within 0.1 m and 10° with a stability margin of 2 cm.
    pub fn expectations(&self) -> Expectations {
        let defaults = Expectations::default();
        let (goal_tolerance_m, goal_tolerance_deg, min_stability_margin_m) = match self.outcome {
            Outcome::Reach => (0.1, 10.0, 0.02),
            Outcome::NoPath => (
                defaults.goal_tolerance_m,
                defaults.goal_tolerance_deg,
                defaults.min_stability_margin_m,
            ),
        };
        Expectations {
            outcome: self.outcome,
            goal_tolerance_m,
            goal_tolerance_deg,
            min_stability_margin_m,
            timeout_s: self.timeout_s,
            ..defaults
        }
    }

    /// The scenario file's text (deterministic: same case, same bytes).
    ///
    /// # Errors
    /// [`GenerateError::Toml`] if serde cannot write it (a generator bug).
    pub fn to_toml(&self) -> Result<String, GenerateError> {
        let file = CaseFile {
            class: self.class,
            name: &self.name,
            description: &self.description,
            map: self.map,
            start: self.start,
            goal: self.goal,
            terrain: self.terrain.iter().map(|p| &p.primitive).collect(),
            params: self
                .class
                .models()
                .map(|(step_model, foot_model)| NamedModels { step_model, foot_model }),
            expect: self.expectations(),
        };
        let body = toml::to_string(&file)
            .map_err(|e| GenerateError::Toml { name: self.name.clone(), reason: e.to_string() })?;
        let params: Vec<String> =
            self.parameters.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        let mut text = format!(
            "# Written by `momaro generate --class {} --seed {} --count 1` (draw {} of the seed).\n# Drawn: {}.\n",
            self.class,
            self.seed,
            self.draw,
            params.join(", ")
        );
        // Each primitive's note above its table: serde writes the tables in order.
        let mut notes = self.terrain.iter().map(|p| &p.note);
        for line in body.lines() {
            if line == "[[terrain]]"
                && let Some(note) = notes.next()
            {
                text.push_str(&format!("# {}\n", note.replace('\n', " ")));
            }
            text.push_str(line);
            text.push('\n');
        }
        Ok(text)
    }

    /// The case's file parsed as a scenario at `dir/{file_name}`.
    ///
    /// # Errors
    /// [`GenerateError::Toml`] or [`GenerateError::Scenario`] if the text cannot be
    /// written or does not parse and validate (a generator bug).
    pub fn scenario(&self, dir: &Path) -> Result<Scenario, GenerateError> {
        Scenario::parse(&self.to_toml()?, &dir.join(self.file_name()))
            .map_err(|e| GenerateError::Scenario { reason: e.to_string() })
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::case;
    use super::*;
    use crate::params::Params;

    /// The scenario a case describes, built from its fields rather than from its file.
    fn expected(c: &GeneratedCase) -> Scenario {
        let terrain: Vec<Primitive> = c.terrain.iter().map(|p| p.primitive.clone()).collect();
        let named = c.class.models();
        let defaults = Params::default();
        let (foot_model, step_model) =
            named.map_or((defaults.foot_model, defaults.step_model), |(step, foot)| (foot, step));
        Scenario {
            name: c.name.clone(),
            path: Path::new("gen").join(c.file_name()),
            description: c.description.clone(),
            class: Some(c.class.name().to_owned()),
            map: c.map,
            start: c.start.pose(),
            goal: c.goal.pose(),
            terrain,
            params: Params { foot_model, step_model, ..defaults },
            named_models: crate::scenario::NamedModels {
                foot: named.is_some(),
                step: named.is_some(),
            },
            expect: c.expectations(),
        }
    }

    #[test]
    fn the_file_loads_as_the_scenario_the_case_describes() {
        for class in Class::ALL {
            for seed in [1, 2, 3, 777, 30_000] {
                let c = case(class, seed);
                let s = c.scenario(Path::new("gen")).unwrap();
                assert_eq!(s, expected(&c), "{}", c.name);
            }
        }
    }

    #[test]
    fn the_file_has_its_comments_and_serde_tables() {
        let c = case(Class::Stairs, 5);
        let text = c.to_toml().unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[0].starts_with("# Written by `momaro generate --class stairs --seed 5"));
        assert!(lines[1].starts_with("# Drawn: mid_landing_after = "), "{}", lines[1]);
        // A note above every primitive's table, in order.
        let notes: Vec<&str> = lines
            .windows(2)
            .filter(|w| w[1] == "[[terrain]]")
            .map(|w| w[0].strip_prefix("# ").unwrap_or_else(|| panic!("{text}")))
            .collect();
        let want: Vec<&str> = c.terrain.iter().map(|p| p.note.as_str()).collect();
        assert_eq!(notes, want);
        assert!(
            text.contains("\n[params]\nstep_model = \"stairs\"\nfoot_model = \"wheel_pair\"\n")
        );
        // Classes that name no model write no [params].
        assert!(!case(Class::Clutter, 5).to_toml().unwrap().contains("[params]"));
    }
}
