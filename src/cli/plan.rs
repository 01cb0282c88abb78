//! `momaro plan` (the hybrid plan, and with `--detailed` its keyframes) and `momaro run`
//! (the scenario in closed loop).

use super::args::*;
use super::report::*;
use crate::jobs;
use anyhow::Context as _;

/// `momaro plan`, and with `--detailed` the path expanded into keyframes.
///
/// # Errors
/// Bad input, or planning that could not be carried out.
pub fn plan(args: PlanArgs) -> anyhow::Result<bool> {
    let PlanArgs { scenario, planner, rerun, expansions, json, detailed, model } = args;
    if detailed {
        let opts = planner.options();
        let d = load(&scenario)
            .and_then(|sc| {
                let mut sim = crate::sim::Simulation::robot_only(&model.model)?;
                let image = expansions.as_deref();
                let d = jobs::detailed::run(&sc, &mut sim, &opts, image).map_err(|e| match e {
                    jobs::detailed::DetailedJobError::Plan(p) => plan_error(p),
                    other => anyhow::Error::new(other),
                })?;
                Ok((sc, d))
            })
            .inspect_err(|e| print_plan_failure(json, &scenario, e));
        let (sc, d) = d?;
        if let Some(path) = rerun {
            jobs::detailed::record(&sc, &d, &path)
                .with_context(|| format!("recording {}", path.display()))?;
        }
        if json {
            print_json(&d)?;
        } else {
            let k = &d.detailed;
            say!("scenario            {} ({})", d.plan.scenario, d.plan.algorithm);
            say!("path                {} poses, {} steps", d.plan.path.len(), d.plan.steps);
            say!("keyframes           {} over {:.1} s", k.keyframes.len(), k.duration_s);
            say!(
                "min margin          {:.3} m (keyframes {:.3} m, three contacts {:.3} m)",
                k.min_margin_m,
                k.min_keyframe_margin_m,
                k.min_three_contact_margin_m
            );
            say!("postures checked    {}", k.samples_checked);
        }
        Ok(true)
    } else {
        let opts = planner.options();
        let planned = load(&scenario)
            .and_then(|sc| {
                let robot = robot(&model.model)?;
                let image = expansions.as_deref();
                let summary = jobs::plan::run(&sc, &robot, &opts, image).map_err(|e| match e {
                    jobs::plan::PlanJobError::Plan(p) => plan_error(p),
                    other => anyhow::Error::new(other),
                })?;
                Ok((sc, robot, summary))
            })
            .inspect_err(|e| print_plan_failure(json, &scenario, e));
        let (sc, robot, summary) = planned?;
        if let Some(path) = rerun {
            jobs::plan_recording::record(&sc, &robot, &summary, &path)
                .with_context(|| format!("recording {}", path.display()))?;
        }
        if json {
            print_json(&summary)?;
        } else {
            say!("scenario            {} ({})", summary.scenario, summary.algorithm);
            say!(
                "models              foot {}, step {}",
                summary.foot_model.name(),
                summary.step_model.name()
            );
            for s in &summary.solutions {
                say!(
                    "solution            ε {:.3}  cost {:.3}  {:.1} ms  {} expansions",
                    s.epsilon,
                    s.cost,
                    s.time_s * 1e3,
                    s.expansions
                );
            }
            say!(
                "path                {} poses, {} steps, cost {:.3}",
                summary.path.len(),
                summary.steps,
                summary.cost
            );
            say!(
                "planning            {:.1} ms ({})",
                summary.planning_time_s * 1e3,
                summary.termination
            );
        }
        Ok(true)
    }
}

/// `momaro run`: exit status true only if the scenario's expectations hold.
///
/// # Errors
/// Bad input, or a job that could not be carried out.
pub fn run(args: RunArgs) -> anyhow::Result<bool> {
    let RunArgs { scenario, planner, noise, rerun, json, model } = args;
    let opts = crate::closed_loop::RunOptions {
        rerun,
        progress: !json,
        noise,
        ..crate::closed_loop::RunOptions::new(planner.options(), model.model)
    };
    let s = match load(&scenario).and_then(|sc| jobs::run::run(&sc, &opts).map_err(run_error)) {
        Ok(s) => s,
        Err(e) => {
            if json {
                print_json(&error_summary(&scenario, &e))?;
            }
            return Err(e);
        }
    };
    if json {
        print_json(&s)?;
    } else {
        say!("scenario            {}", s.scenario);
        say!("result              {}", if s.passed { "PASS" } else { "FAIL" });
        say!(
            "plan                cost {:.3}, {} steps, {:.1} ms",
            s.plan_cost,
            s.plan_steps,
            s.planning_time_s * 1e3
        );
        say!(
            "goal error          {:.3} m, {:.1}°",
            s.goal_position_error_m,
            s.goal_heading_error_rad.to_degrees()
        );
        say!("stability margin    min {:.3} m", s.min_stability_margin_m);
        say!(
            "steps               {} of {} executed, {} aborted, {} replans",
            s.steps_executed,
            s.steps_planned,
            s.steps_aborted,
            s.replans
        );
        if let Some(f) = &s.failure {
            say!("stopped             {f}");
        }
        if s.static_violation_s > 0.0 {
            say!(
                "static violations   {:.3} s, worst {:.3} m",
                s.static_violation_s,
                s.worst_static_violation_m
            );
        }
        say!(
            "tracking error      max {:.3} m, mean {:.3} m",
            s.max_tracking_error_m,
            s.mean_tracking_error_m
        );
        say!(
            "sim time            {:.1} s in {:.1} s wall (x{:.1} real time)",
            s.sim_time_s,
            s.wall_time_s,
            s.real_time_factor
        );
        for e in &s.expectations {
            say!("  {} {:<22} {}", if e.passed { "ok  " } else { "FAIL" }, e.name, e.detail);
        }
    }
    Ok(s.passed)
}
