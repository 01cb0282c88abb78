//! The binary as users call it: bad input gives a clear error naming the file and field and
//! exit code 2, never a panic; a recording verifies with Rerun's own checker.

mod common;

use std::path::Path;
use std::process::{Command, Output};

fn momaro(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_momaro")).args(args).output().expect("binary runs")
}

const GOOD: &str = r#"
[map]
x_min = -1.0
x_max = 3.0
y_min = -2.0
y_max = 2.0
[start]
x = 0.0
y = 0.0
[goal]
x = 2.0
y = 0.0
[[terrain]]
kind = "box"
center = [1.0, 1.5]
size = [0.4, 0.4]
height = 0.2
"#;

fn expect_bad_input(name: &str, text: &str, must_mention: &[&str]) {
    let dir = common::temp_dir(&format!("cli_{name}"));
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = momaro(&["sim", path.to_str().unwrap(), "--duration", "0.1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{name}: exit {:?}, stderr: {stderr}",
        out.status.code()
    );
    assert!(!stderr.contains("panicked"), "{name}: panicked: {stderr}");
    assert!(
        stderr.contains(&format!("{name}.toml")),
        "{name}: error does not name the file: {stderr}"
    );
    for m in must_mention {
        assert!(stderr.contains(m), "{name}: error does not mention `{m}`: {stderr}");
    }
}

#[test]
fn missing_scenario_file() {
    let out = momaro(&["sim", "/no/such/scenario.toml"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("/no/such/scenario.toml"), "{stderr}");
}

#[test]
fn malformed_toml() {
    expect_bad_input("malformed", "[map\nx_min = 1", &["malformed"]);
}

#[test]
fn wrong_type() {
    expect_bad_input("wrong_type", &GOOD.replace("x = 2.0", "x = \"two\""), &["x"]);
}

#[test]
fn unknown_key() {
    expect_bad_input("unknown_key", &GOOD.replace("[goal]", "[goal]\nz = 1.0"), &["z"]);
}

#[test]
fn negative_size() {
    expect_bad_input(
        "negative_size",
        &GOOD.replace("size = [0.4, 0.4]", "size = [0.4, -0.4]"),
        &["terrain[0].size"],
    );
}

#[test]
fn goal_outside_the_map() {
    expect_bad_input(
        "goal_outside",
        &GOOD.replace("x = 2.0", "x = 20.0"),
        &["goal", "outside the map"],
    );
}

#[test]
fn nan_value() {
    expect_bad_input(
        "nan_value",
        &GOOD.replace("height = 0.2", "height = nan"),
        &["terrain[0].height"],
    );
}

#[test]
fn start_inside_an_obstacle() {
    let text = GOOD
        .replace("center = [1.0, 1.5]", "center = [0.0, 0.0]")
        .replace("height = 0.2", "height = 0.6");
    expect_bad_input("start_inside", &text, &["start", "inside"]);
}

#[test]
fn missing_model_file() {
    let scenario = common::root().join("scenarios/flat.toml");
    let out = momaro(&[
        "sim",
        scenario.to_str().unwrap(),
        "--model",
        "/no/such/momaro.xml",
        "--duration",
        "0.1",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("/no/such/momaro.xml") && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn bad_drive_option() {
    let scenario = common::root().join("scenarios/flat.toml");
    let out = momaro(&["sim", scenario.to_str().unwrap(), "--drive", "0.5,nan,0"]);
    assert_eq!(out.status.code(), Some(2));
    let out = momaro(&["sim", scenario.to_str().unwrap(), "--duration", "-1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--duration"), "{stderr}");
}

#[test]
fn bench_probe_times_each_file_and_the_suite() {
    // A drive and a closed room: one path, one "no path" (refused at once), each a row;
    // the suite's median of two rows is the upper one, the larger time.
    let flat = common::root().join("scenarios/flat.toml");
    let closed = common::root().join("scenarios/closed_room.toml");
    let out = momaro(&[
        "bench",
        "probe",
        flat.to_str().unwrap(),
        closed.to_str().unwrap(),
        "--repeats",
        "2",
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    // A progress line per file as it is done, sorted like `check`'s suite.
    let progress: Vec<&str> = stderr.lines().filter(|l| l.starts_with('[')).collect();
    assert_eq!(progress.len(), 2, "{stderr}");
    assert!(progress[0].starts_with("[1/2] closed_room") && progress[0].contains("no_path"));
    assert!(progress[1].starts_with("[2/2] flat") && progress[1].contains("path"));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let rows = v["rows"].as_array().expect("rows");
    let row = |name: &str| rows.iter().find(|r| r["scenario"] == name).expect(name).clone();
    let (flat_row, closed_row) = (row("flat"), row("closed_room"));
    assert_eq!(flat_row["outcome"], "path");
    assert!(flat_row["expansions"].as_u64().is_some_and(|e| e > 0), "{flat_row}");
    assert!(flat_row["cost"].as_f64().is_some_and(|c| c > 0.0), "{flat_row}");
    assert_eq!(closed_row["outcome"], "no_path");
    assert!(closed_row["cost"].is_null() && closed_row["search_s"].is_null());
    // The search alone is part of the whole plan's wall time; one row has a search time.
    let search = flat_row["search_s"].as_f64().expect("search time");
    assert!(search > 0.0 && search <= flat_row["time_s"].as_f64().unwrap(), "{flat_row}");
    assert_eq!(v["median_search_s"].as_f64(), Some(search));
    assert_eq!(v["paths"], 1);
    assert_eq!(v["repeats"], 2);
    let times: Vec<f64> = rows.iter().map(|r| r["time_s"].as_f64().unwrap()).collect();
    assert_eq!(v["median_s"].as_f64().unwrap(), times[0].max(times[1]));
    assert!((v["mean_s"].as_f64().unwrap() - (times[0] + times[1]) / 2.0).abs() < 1e-12);
    let out = momaro(&["bench", "probe", flat.to_str().unwrap(), "--repeats", "0"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("repeats") && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn bench_scaling_plans_one_course_on_growing_maps_and_growing_courses_on_one_map() {
    // flat's course on 5 and 7 m maps, then 1 and 2 m straight drives on a 7 m map.
    let out = momaro(&[
        "bench",
        "scaling",
        "--map-sizes",
        "5,7",
        "--lengths",
        "1,2",
        "--length-map",
        "7",
        "--repeats",
        "1",
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_eq!(stderr.lines().filter(|l| l.starts_with('[')).count(), 4, "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let rows = v["rows"].as_array().expect("rows");
    let field = |k: &str| rows.iter().map(|r| r[k].clone()).collect::<Vec<_>>();
    assert_eq!(field("sweep"), ["area", "area", "length", "length"]);
    assert_eq!(field("map_m"), [5.0, 7.0, 7.0, 7.0]);
    // 2.5 cm cells: 200² and 280².
    assert_eq!(field("cells"), [40_000, 78_400, 78_400, 78_400]);
    let lengths: Vec<f64> = field("length_m").iter().map(|l| l.as_f64().unwrap()).collect();
    assert!((lengths[0] - 1.5f64.hypot(1.2)).abs() < 1e-9 && lengths[0] == lengths[1]);
    assert!((lengths[2] - 1.0).abs() < 1e-9 && (lengths[3] - 2.0).abs() < 1e-9);
    for r in rows {
        assert_eq!(r["outcome"], "path", "{r}");
        let part: f64 = ["maps_s", "heuristic_setup_s", "search_s"]
            .iter()
            .map(|k| r[*k].as_f64().unwrap())
            .sum();
        assert!(part > 0.0 && part <= r["time_s"].as_f64().unwrap(), "{r}");
        // A warm replan from the path's middle, on the tables the cold plan left.
        assert!(r["warm_replan_s"].as_f64().is_some_and(|t| t > 0.0), "{r}");
        assert!(r["warm_replan_expansions"].as_u64().is_some(), "{r}");
    }
    // The same course on both maps: the same plan.
    assert_eq!(rows[0]["cost"], rows[1]["cost"]);
    assert!(v["area_ratio"].as_f64().is_some() && v["length_ratio"].as_f64().is_some());
    // A map too small for its course is refused by name.
    let out = momaro(&["bench", "scaling", "--map-sizes", "3", "--lengths", "1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("map_sizes") && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn bad_planner_option_names_the_parameter() {
    let scenario = common::root().join("scenarios/flat.toml");
    for bad in ["nan", "-1"] {
        let out = momaro(&["plan", scenario.to_str().unwrap(), "--step-cost-factor", bad]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {stderr}");
        assert!(
            stderr.contains("step_cost_factor") && !stderr.contains("panicked"),
            "{bad}: {stderr}"
        );
    }
    let out = momaro(&["bench", "plan", scenario.to_str().unwrap(), "--repeats", "0"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("repeats") && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn models_are_checked_in_the_file_and_on_the_command_line() {
    expect_bad_input(
        "bad_foot_model",
        &format!("{GOOD}\n[params]\nfoot_model = \"wheels\"\n"),
        &["foot_model", "`paper`", "`wheel_pair`"],
    );
    let scenario = common::root().join("scenarios/flat.toml");
    let out = momaro(&["plan", scenario.to_str().unwrap(), "--foot-model", "wheels"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("wheel_pair") && !stderr.contains("panicked"), "{stderr}");
    let out = momaro(&["plan", scenario.to_str().unwrap(), "--step-model", "steps"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("stairs") && !stderr.contains("panicked"), "{stderr}");
    let plan = |models: &[&str]| {
        let path = scenario.to_str().unwrap();
        let args = [&["plan", path, "--final-epsilon", "3", "--json"][..], models].concat();
        let out = momaro(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
        (v["foot_model"].clone(), v["step_model"].clone())
    };
    // Flat ground names no models and has no stairs: the paper's.
    assert_eq!(plan(&[]), ("paper".into(), "paper".into()));
    let overridden = plan(&["--foot-model", "wheel_pair", "--step-model", "stairs"]);
    assert_eq!(overridden, ("wheel_pair".into(), "stairs".into()));
}

#[test]
fn json_summary_has_the_documented_fields() {
    let scenario = common::root().join("scenarios/flat.toml");
    let out = momaro(&["sim", scenario.to_str().unwrap(), "--duration", "1", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    for key in [
        "sim_time_s",
        "wall_time_s",
        "real_time_factor",
        "base_start",
        "base_end",
        "min_wheels_in_contact",
        "min_stability_margin_m",
        "upright",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert_eq!(v["base_start"].as_array().map(Vec::len), Some(4));
}

#[test]
fn recording_verifies_with_rerun() {
    let rerun = common::root().join("third_party/venv/bin/rerun");
    assert!(
        rerun.is_file(),
        "the Rerun CLI is missing: run `tools/setup --rerun-cli` (the README's test command does)"
    );
    let dir = common::temp_dir("rrd");
    let rrd = dir.join("flat.rrd");
    let scenario = common::root().join("scenarios/flat.toml");
    let out = momaro(&[
        "sim",
        scenario.to_str().unwrap(),
        "--duration",
        "1",
        "--drive",
        "0.3,0,0.2",
        "--rerun",
        rrd.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        Path::new(&rrd).metadata().map(|m| m.len() > 1000).unwrap_or(false),
        "recording is empty"
    );
    let verify = Command::new(&rerun)
        .args(["rrd", "verify", rrd.to_str().unwrap()])
        .output()
        .expect("rerun runs");
    assert!(
        verify.status.success(),
        "rerun rrd verify failed: {}{}",
        String::from_utf8_lossy(&verify.stdout),
        String::from_utf8_lossy(&verify.stderr)
    );
}

#[test]
fn closed_stdout_is_not_a_panic() {
    // `momaro ... | head -1`: the reader goes away before the output is written.
    let scenario = common::root().join("scenarios/flat.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_momaro"))
        .args(["costmap", scenario.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("binary runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("waits");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(out.status.success(), "{stderr}");
}

#[test]
fn run_recording_verifies_with_rerun_and_json_has_the_documented_fields() {
    let rerun = common::root().join("third_party/venv/bin/rerun");
    assert!(rerun.is_file(), "the Rerun CLI is missing: run `tools/setup --rerun-cli`");
    let dir = common::temp_dir("run_rrd");
    let rrd = dir.join("corridor.rrd");
    let scenario = common::root().join("scenarios/corridor.toml");
    let out =
        momaro(&["run", scenario.to_str().unwrap(), "--json", "--rerun", rrd.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    for key in [
        "reached_goal",
        "goal_position_error_m",
        "goal_heading_error_rad",
        "sim_time_s",
        "wall_time_s",
        "real_time_factor",
        "min_stability_margin_m",
        "tipped",
        "body_collisions",
        "steps_executed",
        "planning_time_s",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    let verify = Command::new(&rerun)
        .args(["rrd", "verify", rrd.to_str().unwrap()])
        .output()
        .expect("rerun runs");
    assert!(verify.status.success(), "{}", String::from_utf8_lossy(&verify.stderr));
}

#[test]
fn run_steps_up_where_the_ramp_is_far() {
    // ramp_far: the ramp is a clearly longer detour, so the plan steps onto the 0.2 m
    // platform (issue 7: "with a far ramp: steps up"), and the run executes every step.
    let scenario = common::root().join("scenarios/ramp_far.toml");
    let out = momaro(&[
        "run",
        scenario.to_str().unwrap(),
        "--final-epsilon",
        "3",
        "--time-limit",
        "300",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(out.status.code(), Some(0), "{v:#}");
    assert_eq!(v["passed"], true);
    let planned = v["steps_planned"].as_u64().expect("steps_planned");
    assert!(planned >= 2, "{v:#}");
    assert_eq!(v["steps_executed"].as_u64(), Some(planned));
    assert_eq!(v["tipped"], false);
}

/// `check --json` of `files` with `jobs` workers: exit code and the report.
fn check_json(files: &[&str], extra: &[&str]) -> (Option<i32>, serde_json::Value, String) {
    let mut args = vec!["check", "--final-epsilon", "3", "--time-limit", "300", "--json"];
    args.extend_from_slice(extra);
    args.extend_from_slice(files);
    let out = momaro(&args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let v = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON ({e}): {stderr}"));
    (out.status.code(), v, stderr)
}

/// `v` without its wall-clock fields, at any depth.
fn without_timing(v: &serde_json::Value) -> serde_json::Value {
    match v {
        serde_json::Value::Object(m) => m
            .iter()
            .filter(|(k, _)| {
                !matches!(k.as_str(), "wall_time_s" | "real_time_factor" | "planning_time_s")
            })
            .map(|(k, v)| (k.clone(), without_timing(v)))
            .collect(),
        serde_json::Value::Array(a) => a.iter().map(without_timing).collect(),
        other => other.clone(),
    }
}

#[test]
fn check_rows_do_not_depend_on_the_worker_count() {
    let flat = common::root().join("scenarios/flat.toml");
    let poles = common::root().join("scenarios/poles.toml");
    // Given in reverse: the rows come in path order.
    let files = [poles.to_str().unwrap(), flat.to_str().unwrap()];
    let (code1, one, stderr1) = check_json(&files, &["--jobs", "1"]);
    assert_eq!(code1, Some(0), "{stderr1}\n{one:#}");
    let (code2, two, stderr2) = check_json(&files, &["--jobs", "2"]);
    assert_eq!(code2, Some(0), "{stderr2}\n{two:#}");
    assert_eq!((one["jobs"].as_u64(), two["jobs"].as_u64()), (Some(1), Some(2)));
    assert_eq!(one["shard"], serde_json::Value::Null);
    let names: Vec<_> = one["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(|r| r["scenario"].as_str().unwrap_or_default().to_owned())
        .collect();
    assert_eq!(names, ["flat", "poles"]);
    for r in one["rows"].as_array().expect("rows") {
        assert_eq!(r["result"], "pass", "{r:#}");
        assert_eq!(r["class"], serde_json::Value::Null);
        assert!(r["path"].as_str().is_some_and(|p| p.ends_with(".toml")), "{r:#}");
    }
    assert_eq!(without_timing(&one["rows"]), without_timing(&two["rows"]));
    assert_eq!(one["total"], two["total"]);
    assert_eq!(one["total"]["cases"], 2);
    assert_eq!(one["total"]["passed"], 2);
    assert_eq!(one["classes"]["-"], one["total"]);
    // One progress line per scenario on stderr.
    assert_eq!(stderr2.lines().filter(|l| l.starts_with('[')).count(), 2, "{stderr2}");
}

#[test]
fn check_shard_out_of_range_or_malformed_is_bad_input() {
    let flat = common::root().join("scenarios/flat.toml");
    for bad in ["0/2", "3/2", "1/0", "two/3", "1"] {
        let out = momaro(&["check", "--shard", bad, flat.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {stderr}");
        assert!(stderr.contains("--shard") && !stderr.contains("panicked"), "{bad}: {stderr}");
    }
}

#[test]
fn check_reports_an_invalid_file_as_a_row_and_runs_the_rest() {
    let dir = common::temp_dir("check_invalid");
    std::fs::write(dir.join("broken.toml"), GOOD.replace("x = 2.0", "x = 20.0")).unwrap();
    std::fs::write(dir.join("notes.txt"), "not a scenario").unwrap();
    let flat = common::root().join("scenarios/flat.toml");
    let (code, v, stderr) =
        check_json(&[dir.to_str().unwrap(), flat.to_str().unwrap()], &["--shard", "1/1"]);
    assert_eq!(code, Some(2), "{stderr}\n{v:#}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(v["shard"], serde_json::json!([1, 1]));
    let rows = v["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 2, "{v:#}");
    let broken = rows.iter().find(|r| r["scenario"] == "broken").expect("broken row");
    assert_eq!(broken["result"], "invalid");
    let msg = broken["failure"].as_str().unwrap_or_default();
    assert!(msg.contains("broken.toml") && msg.contains("goal"), "{msg}");
    let flat = rows.iter().find(|r| r["scenario"] == "flat").expect("flat row");
    assert_eq!(flat["result"], "pass", "{flat:#}");
    assert_eq!((v["total"]["invalid"].as_u64(), v["total"]["passed"].as_u64()), (Some(1), Some(1)));
}

#[test]
fn generate_writes_one_loadable_file_per_class_and_repeats_byte_for_byte() {
    let dirs = [common::temp_dir("generate_a"), common::temp_dir("generate_b")];
    for dir in &dirs {
        let out =
            momaro(&["generate", "--seed", "1", "--count", "8", "--out", dir.to_str().unwrap()]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let mut names: Vec<String> = std::fs::read_dir(&dirs[0])
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 8, "{names:?}");
    let mut classes = Vec::new();
    for name in &names {
        let path = dirs[0].join(name);
        let s = momaro::scenario::Scenario::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let class = s.class.clone().expect("a class");
        assert!(name.starts_with(&format!("{class}_0000")), "{name}");
        classes.push(class);
        let again = std::fs::read(dirs[1].join(name)).expect("the second run wrote it too");
        assert_eq!(std::fs::read(&path).unwrap(), again, "{name} differs between runs");
    }
    classes.sort();
    let mut all: Vec<String> =
        momaro::scenario::generate::Class::NAMES.iter().map(|s| s.to_string()).collect();
    all.sort();
    assert_eq!(classes, all);
    // The JSON summary counts one file per class.
    let out = momaro(&[
        "generate",
        "--seed",
        "1",
        "--count",
        "8",
        "--out",
        dirs[1].to_str().unwrap(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    assert_eq!(v["files"].as_array().map(Vec::len), Some(8));
    let per_class = v["per_class"].as_array().expect("per_class");
    assert_eq!(per_class.len(), 8);
    assert!(per_class.iter().all(|c| c["count"] == 1), "{v:#}");
}

#[test]
fn generate_rejects_bad_input_with_exit_code_2() {
    let dir = common::temp_dir("generate_bad");
    let d = dir.to_str().unwrap();
    for args in [
        vec!["generate", "--count", "0", "--out", d],
        vec!["generate", "--class", "ladder", "--out", d],
        vec!["generate", "--seed", "18446744073709551615", "--count", "2", "--out", d],
    ] {
        let out = momaro(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    let out = momaro(&["generate", "--count", "0", "--out", d]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("count"));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
}

/// Width, height and the pixels that are neither grey nor olive (the expansion colours)
/// of an RGB PNG.
fn coloured_pixels(path: &Path) -> (u32, u32, usize) {
    let file = std::fs::File::open(path).expect("the PNG was written");
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let coloured = buf[..info.buffer_size()]
        .chunks(3)
        .filter(|p| !(p[0] == p[1] && p[1] == p[2]) && *p != [128, 128, 0])
        .count();
    (info.width, info.height, coloured)
}

#[test]
fn plan_draws_where_its_search_went_with_or_without_a_path() {
    let dir = common::temp_dir("cli_expansions");
    // A path: the expanded cells are drawn over the map (4 m × 4 m plus the r_N margin
    // on each side, 2.5 cm cells).
    let flat = common::root().join("scenarios/flat.toml");
    let png = dir.join("flat.png");
    let out = momaro(&["plan", flat.to_str().unwrap(), "--expansions", png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let sc = common::scenario("flat");
    let (w, h, coloured) = coloured_pixels(&png);
    let m = &sc.map;
    let cells = |a: f64, b: f64| ((b - a) / 0.025).round() as u32;
    assert!(w >= cells(m.x_min, m.x_max) && h >= cells(m.y_min, m.y_max), "{w} x {h}");
    assert!(coloured > 0, "no expanded cell drawn");
    // No path (a closed room, proved at once): the image is still written, exit 1.
    let room = common::root().join("scenarios/closed_room.toml");
    let png = dir.join("room.png");
    let out = momaro(&["plan", room.to_str().unwrap(), "--expansions", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(png.exists(), "no image without a path");
    // An unwritable path names the file, exit 2 or 1, no panic.
    let out = momaro(&["plan", flat.to_str().unwrap(), "--expansions", "/nonexistent-dir/x.png"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("/nonexistent-dir/x.png"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// `plan --json` of `args`: the exit code and the object on stdout.
fn plan_json(args: &[&str]) -> (Option<i32>, serde_json::Value) {
    let mut all = vec!["plan"];
    all.extend_from_slice(args);
    all.push("--json");
    let out = momaro(&all);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let v = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{args:?}: {e}: {stdout}"));
    (out.status.code(), v)
}

#[test]
fn plan_json_prints_one_object_whatever_happens() {
    // No path (a closed room): exit 1, the failure's kind and message on stdout.
    let room = common::root().join("scenarios/closed_room.toml");
    let (code, v) = plan_json(&[room.to_str().unwrap()]);
    assert_eq!((code, v["failure_kind"].as_str()), (Some(1), Some("no_path")), "{v}");
    assert!(v["failure"].as_str().is_some_and(|f| f.contains("closed_room.toml")), "{v}");
    // ...and what the proof took.
    assert!(v["failure"].as_str().is_some_and(|f| f.contains(" expansions, ")), "{v}");
    // The time limit before any path: exit 1, `planning_time_limit`.
    let stairs = common::root().join("scenarios/staircase.toml");
    let (code, v) = plan_json(&[stairs.to_str().unwrap(), "--time-limit", "0.001"]);
    assert_eq!((code, v["failure_kind"].as_str()), (Some(1), Some("planning_time_limit")), "{v}");
    // The expansion budget before any path: reported as the time limit is, whatever the
    // machine's speed; a budget of none is bad input.
    let (code, v) = plan_json(&[stairs.to_str().unwrap(), "--max-expansions", "50"]);
    assert_eq!((code, v["failure_kind"].as_str()), (Some(1), Some("planning_time_limit")), "{v}");
    let said = v["failure"].as_str().unwrap_or_default();
    assert!(said.contains("within the expansion budget of 50"), "{v}");
    let (code, v) = plan_json(&[stairs.to_str().unwrap(), "--max-expansions", "0"]);
    assert_eq!((code, v["failure_kind"].as_str()), (Some(2), Some("invalid_input")), "{v}");
    // Bad input, with and without `--detailed`: exit 2, `invalid_input` naming the file.
    let dir = common::temp_dir("cli_plan_json");
    let bad = dir.join("broken.toml");
    std::fs::write(&bad, "[map]\nx_min = 0.0\n").unwrap();
    for detailed in [false, true] {
        let mut args = vec![bad.to_str().unwrap()];
        if detailed {
            args.push("--detailed");
        }
        let (code, v) = plan_json(&args);
        assert_eq!((code, v["failure_kind"].as_str()), (Some(2), Some("invalid_input")), "{v}");
        assert!(v["failure"].as_str().is_some_and(|f| f.contains("broken.toml")), "{v}");
    }
}
