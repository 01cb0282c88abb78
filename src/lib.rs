//! momaro: a closed-loop simulator of hybrid driving-stepping locomotion for the robot
//! Momaro, after Klamt & Behnke, "Anytime Hybrid Driving-Stepping Locomotion Planning"
//! (IROS 2017). See ARCHITECTURE.md for how the modules fit together.

pub mod cli;
pub mod closed_loop;
pub mod control;
pub mod cost;
pub mod feasibility;
pub mod geometry;
pub mod jobs;
pub mod monitor;
pub mod motion;
pub mod params;
pub mod path;
pub mod planner;
pub mod posture;
pub mod progress;
pub mod render;
pub mod rng;
pub mod robot;
pub mod scenario;
pub mod search;
pub mod sim;
pub mod support;
pub mod terrain;
pub mod urdf_export;
pub mod viz;
