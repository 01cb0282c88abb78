//! The height map of a scenario's world as the closed loop uses it: the map extent plus a
//! margin of r_N on every side (the executor looks up the ground under wherever the wheels
//! are, also beyond the planner's map), rasterised from the scenario's primitives.

use super::heightmap::HeightMap;
use super::rasterise::{RasteriseError, rasterise};
use crate::scenario::Scenario;

/// Grid of a scenario's height map: origin, cells along x and y. Covers the map extent plus
/// a margin of r_N.
pub fn map_grid(scenario: &Scenario) -> ([f64; 2], [usize; 2]) {
    let p = &scenario.params;
    let margin = p.r_n_m;
    let m = &scenario.map;
    let origin = [m.x_min - margin, m.y_min - margin];
    let cells = |span: f64| ((span + 2.0 * margin) / p.grid_resolution_m).ceil().max(1.0) as usize;
    (origin, [cells(m.x_max - m.x_min), cells(m.y_max - m.y_min)])
}

/// The scenario's rasterised height map over [`map_grid`].
///
/// # Errors
/// [`RasteriseError`] where a primitive cannot be rasterised.
pub fn scenario_map(scenario: &Scenario) -> Result<HeightMap, RasteriseError> {
    let (origin, [nx, ny]) = map_grid(scenario);
    let res = scenario.params.grid_resolution_m;
    rasterise(&scenario.terrain, origin, [nx as f64 * res, ny as f64 * res], res)
}
