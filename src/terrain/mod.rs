//! Terrain as the planner sees it: the 2.5D [`HeightMap`] (2.5 cm cells, `NaN` = unknown)
//! and its two sources, exact rasterisation of scenario primitives ([`rasterise()`]) and
//! ray-cast sensing like the robot's rotating laser ([`sensed`]); [`flights`] reads
//! flights of steps from a map's heights alone.
//!
//! The cost maps (`cost`) are computed from a `HeightMap` and do not care which source
//! made it. The grid convention is defined once, in [`heightmap`].

pub mod flights;
pub mod heightmap;
pub mod rasterise;
pub mod scenario_map;
pub mod sensed;

pub use flights::{FlightRule, Flights, flights};
pub use heightmap::{HeightMap, HeightMapError, HeightMapView, square_window_max};
pub use rasterise::{RasteriseError, rasterise, rasterise_into};
pub use scenario_map::{map_grid, scenario_map};
pub use sensed::{LaserScanner, RayCaster, RayHit, ScanStats, SensedError};
