//! Sweeps: a base case and the values to set in it, expanded into one case per point, with each
//! problem named by the pointer of the request that caused it; and a finished point's summary.

use crate::job::SnapshotInfo;
use fluidbed_api::{PointSummary, SweepRequest};
use fluidbed_core::case::{Case, Problem, Severity};
use serde_json::{Map, Value};

/// One point before it is a job: the values to set (case pointer → value) and, for each, the
/// pointer in the request where that value was given (so a problem with it names that place).
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub set: Map<String, Value>,
    pub origin: Map<String, Value>,
}

fn error(path: &str, value: Value, allowed: &str, message: String) -> Problem {
    Problem { path: path.into(), value, allowed: allowed.into(), message, severity: Severity::Error }
}

/// RFC 6901: `~0` is `~`, `~1` is `/`.
fn escape(token: &str) -> String {
    token.replace('~', "~0").replace('/', "~1")
}

fn tokens(pointer: &str) -> Option<Vec<String>> {
    let rest = pointer.strip_prefix('/')?;
    Some(rest.split('/').map(|t| t.replace("~1", "/").replace("~0", "~")).collect())
}

/// The request's points, at most `max_points`, or every problem with the request.
pub fn expand(req: &SweepRequest, max_points: usize) -> Result<Vec<Point>, Vec<Problem>> {
    let mut problems = Vec::new();
    let check_pointer = |problems: &mut Vec<Problem>, at: &str, pointer: &str| {
        if tokens(pointer).is_none_or(|t| t.iter().all(|t| t.is_empty())) {
            problems.push(error(
                at,
                Value::String(pointer.into()),
                "a JSON pointer into the case such as /gas/superficial_velocity_m_s",
                format!("`{pointer}` is not a pointer to a field of the case"),
            ));
        }
    };
    let points = match (&req.grid, &req.points) {
        (Some(_), Some(_)) | (None, None) => {
            problems.push(error(
                "/grid",
                Value::Null,
                "`grid` or `points`, one of them",
                "give either a grid of values or a list of points".into(),
            ));
            Vec::new()
        }
        (Some(grid), None) => {
            if grid.is_empty() {
                problems.push(error("/grid", Value::Array(vec![]), "at least one axis", "the grid has no axis".into()));
            }
            let mut size: usize = 1;
            for (i, axis) in grid.iter().enumerate() {
                check_pointer(&mut problems, &format!("/grid/{i}/pointer"), &axis.pointer);
                if grid[..i].iter().any(|a| a.pointer == axis.pointer) {
                    problems.push(error(
                        &format!("/grid/{i}/pointer"),
                        Value::String(axis.pointer.clone()),
                        "each pointer once",
                        format!("`{}` is already an axis of the grid", axis.pointer),
                    ));
                }
                if axis.values.is_empty() {
                    problems.push(error(
                        &format!("/grid/{i}/values"),
                        Value::Array(vec![]),
                        "at least one value",
                        "an axis without values".into(),
                    ));
                }
                size = size.saturating_mul(axis.values.len());
            }
            if size > max_points {
                problems.push(error(
                    "/grid",
                    Value::from(size as u64),
                    &format!("at most {max_points} points"),
                    format!("the grid has {size} points; this server takes at most {max_points} in one sweep"),
                ));
            }
            if !problems.is_empty() {
                return Err(problems);
            }
            // Every combination, the first axis slowest.
            (0..size)
                .map(|mut k| {
                    let mut chosen = vec![0; grid.len()];
                    for (a, axis) in grid.iter().enumerate().rev() {
                        chosen[a] = k % axis.values.len();
                        k /= axis.values.len();
                    }
                    let mut p = Point { set: Map::new(), origin: Map::new() };
                    for (a, axis) in grid.iter().enumerate() {
                        p.set.insert(axis.pointer.clone(), axis.values[chosen[a]].clone());
                        p.origin.insert(axis.pointer.clone(), Value::String(format!("/grid/{a}/values/{}", chosen[a])));
                    }
                    p
                })
                .collect()
        }
        (None, Some(list)) => {
            if list.is_empty() {
                problems.push(error(
                    "/points",
                    Value::Array(vec![]),
                    "at least one point",
                    "the sweep has no points".into(),
                ));
            }
            if list.len() > max_points {
                problems.push(error(
                    "/points",
                    Value::from(list.len() as u64),
                    &format!("at most {max_points} points"),
                    format!("{} points; this server takes at most {max_points} in one sweep", list.len()),
                ));
            }
            let mut out = Vec::new();
            for (k, set) in list.iter().enumerate() {
                let mut origin = Map::new();
                for pointer in set.keys() {
                    let at = format!("/points/{k}/{}", escape(pointer));
                    check_pointer(&mut problems, &at, pointer);
                    origin.insert(pointer.clone(), Value::String(at));
                }
                out.push(Point { set: set.clone(), origin });
            }
            out
        }
    };
    if problems.is_empty() {
        Ok(points)
    } else {
        Err(problems)
    }
}

/// Set `value` at `pointer` in `doc`, making missing objects on the way (a section the base case
/// leaves at its defaults); an array element must exist.
fn set_at(doc: &mut Value, pointer: &str, value: Value) -> Result<(), String> {
    let tokens = tokens(pointer).ok_or_else(|| format!("`{pointer}` is not a JSON pointer"))?;
    let (last, parents) = tokens.split_last().ok_or_else(|| "an empty pointer".to_string())?;
    let mut at = doc;
    for t in parents {
        at = match at {
            Value::Object(m) => m.entry(t.clone()).or_insert_with(|| Value::Object(Map::new())),
            Value::Array(a) => {
                let len = a.len();
                t.parse::<usize>()
                    .ok()
                    .and_then(|i| a.get_mut(i))
                    .ok_or_else(|| format!("`{t}` is not an index of an array of {len}"))?
            }
            _ => return Err(format!("`{t}` is inside a value that is neither an object nor an array")),
        };
    }
    match at {
        Value::Object(m) => {
            m.insert(last.clone(), value);
            Ok(())
        }
        Value::Array(a) => {
            let len = a.len();
            let slot = last.parse::<usize>().ok().and_then(|i| a.get_mut(i));
            *slot.ok_or_else(|| format!("`{last}` is not an index of an array of {len}"))? = value;
            Ok(())
        }
        _ => Err(format!("the parent of `{last}` is neither an object nor an array")),
    }
}

/// A short label of a point's values, e.g. `superficial_velocity_m_s=0.3`.
pub fn label(set: &Map<String, Value>) -> String {
    set.iter().map(|(p, v)| format!("{}={v}", p.rsplit('/').next().unwrap_or(p))).collect::<Vec<_>>().join(", ")
}

/// The case of point `k`: the base with the point's values set, named after the sweep and the
/// point (unless the point sets the name itself), every problem named by the request's pointer.
pub fn case_of(base: &Value, sweep_name: &str, k: usize, point: &Point) -> Result<Value, Vec<Problem>> {
    let mut doc = base.clone();
    let mut problems = Vec::new();
    for (pointer, value) in &point.set {
        if let Err(why) = set_at(&mut doc, pointer, value.clone()) {
            let at = point.origin[pointer].as_str().unwrap_or("").to_string();
            problems.push(error(&at, Value::String(pointer.clone()), "a pointer to a field of the base case", why));
        }
    }
    if !problems.is_empty() {
        return Err(problems);
    }
    if !point.set.contains_key("/name") {
        if let Some(obj) = doc.as_object_mut() {
            let mut name = format!("{sweep_name} [{k}: {}]", label(&point.set));
            if name.len() > fluidbed_core::case::bounds::MAX_NAME_BYTES {
                let mut cut = fluidbed_core::case::bounds::MAX_NAME_BYTES - 3;
                while !name.is_char_boundary(cut) {
                    cut -= 1;
                }
                name.truncate(cut);
                name.push_str("…]");
            }
            obj.insert("name".into(), Value::String(name));
        }
    }
    Ok(doc)
}

/// A problem of point `k`'s case, named where the request gave the value (a value set by the
/// point) or in `/base` (a field the point leaves as the base has it).
pub fn locate(mut p: Problem, k: usize, point: &Point) -> Problem {
    let given =
        point.origin.iter().find(|(pointer, _)| p.path == **pointer || p.path.starts_with(&format!("{pointer}/")));
    p.message = format!("point {k} ({}): {}", label(&point.set), p.message);
    p.path = match given {
        Some((_, at)) => at.as_str().unwrap_or("").to_string(),
        None => format!("/base{}", p.path),
    };
    p
}

/// The summary of a finished point from its snapshot index: the second half of the run.
pub fn summarize(case: &Case, infos: &[SnapshotInfo]) -> PointSummary {
    let from_s = case.end_time_s / 2.0;
    let window: Vec<&SnapshotInfo> = infos.iter().filter(|s| s.time_s >= from_s).collect();
    let mean_std = |xs: &[f64]| -> (Option<f64>, Option<f64>) {
        if xs.is_empty() {
            return (None, None);
        }
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        (Some(mean), Some(var.sqrt()))
    };
    let dp: Vec<f64> = window.iter().filter_map(|s| s.pressure_drop_pa).collect();
    let heights: Vec<f64> = window.iter().filter_map(|s| s.mean_particle_height_m).collect();
    let (dp_mean, dp_std) = mean_std(&dp);
    PointSummary {
        superficial_velocity_m_s: case.gas.as_ref().map(|g| g.superficial_velocity_m_s),
        from_s,
        to_s: window.last().map_or(from_s, |s| s.time_s),
        samples: window.len() as u64,
        pressure_drop_mean_pa: dp_mean,
        pressure_drop_std_pa: dp_std,
        mean_particle_height_m: mean_std(&heights).0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fluidbed_api::GridAxis;
    use serde_json::json;

    fn grid(axes: &[(&str, Value)]) -> SweepRequest {
        SweepRequest {
            name: None,
            base: json!({}),
            grid: Some(
                axes.iter()
                    .map(|(p, v)| GridAxis { pointer: (*p).into(), values: v.as_array().unwrap().clone() })
                    .collect(),
            ),
            points: None,
        }
    }

    #[test]
    fn a_grid_gives_every_combination_with_the_first_axis_slowest() {
        let req = grid(&[("/a", json!([1, 2])), ("/b/c", json!(["x", "y", "z"]))]);
        let pts = expand(&req, 64).unwrap();
        assert_eq!(pts.len(), 6);
        let pairs: Vec<(Value, Value)> = pts.iter().map(|p| (p.set["/a"].clone(), p.set["/b/c"].clone())).collect();
        assert_eq!(pairs[0], (json!(1), json!("x")));
        assert_eq!(pairs[2], (json!(1), json!("z")));
        assert_eq!(pairs[3], (json!(2), json!("x")));
        assert_eq!(pts[4].origin["/b/c"], json!("/grid/1/values/1"));
    }

    #[test]
    fn a_grid_past_the_limit_is_refused_before_it_is_built() {
        let big: Vec<Value> = (0..1000).map(Value::from).collect();
        let req =
            grid(&[("/a", Value::Array(big.clone())), ("/b", Value::Array(big.clone())), ("/c", Value::Array(big))]);
        let problems = expand(&req, 64).unwrap_err();
        assert_eq!(problems[0].path, "/grid");
        assert!(problems[0].message.contains("1000000000 points"), "{}", problems[0].message);
    }

    #[test]
    fn bad_pointers_and_empty_axes_are_named() {
        let req = grid(&[("gas", json!([1])), ("/a", json!([])), ("/a", json!([2]))]);
        let paths: Vec<String> = expand(&req, 64).unwrap_err().into_iter().map(|p| p.path).collect();
        assert_eq!(paths, ["/grid/0/pointer", "/grid/1/values", "/grid/2/pointer"]);
        let mut both = grid(&[("/a", json!([1]))]);
        both.points = Some(vec![]);
        assert_eq!(expand(&both, 64).unwrap_err()[0].path, "/grid");
    }

    #[test]
    fn a_point_sets_its_values_and_makes_missing_sections() {
        let base = json!({"name": "base", "gas": {"superficial_velocity_m_s": 0.6}, "list": [1, 2]});
        let mut set = Map::new();
        set.insert("/gas/superficial_velocity_m_s".into(), json!(0.3));
        set.insert("/analysis/heights_m".into(), json!([0.01]));
        set.insert("/list/1".into(), json!(5));
        let req = SweepRequest { name: None, base: base.clone(), grid: None, points: Some(vec![set]) };
        let pts = expand(&req, 64).unwrap();
        let case = case_of(&base, "U sweep", 0, &pts[0]).unwrap();
        assert_eq!(case["gas"]["superficial_velocity_m_s"], json!(0.3));
        assert_eq!(case["analysis"]["heights_m"], json!([0.01]));
        assert_eq!(case["list"], json!([1, 5]));
        assert!(case["name"].as_str().unwrap().starts_with("U sweep [0: "), "{}", case["name"]);
        // An index past an array's end is named where the point gave it.
        let mut bad = Map::new();
        bad.insert("/list/7".into(), json!(0));
        let req = SweepRequest { name: None, base: base.clone(), grid: None, points: Some(vec![Map::new(), bad]) };
        let pts = expand(&req, 64).unwrap();
        let problems = case_of(&base, "s", 1, &pts[1]).unwrap_err();
        assert_eq!(problems[0].path, "/points/1/~1list~17");
    }

    #[test]
    fn a_case_problem_is_named_where_its_value_was_given() {
        let req = grid(&[("/gas/superficial_velocity_m_s", json!([0.3, -1.0]))]);
        let pts = expand(&req, 64).unwrap();
        let p = |path: &str| error(path, Value::Null, "", "bad".into());
        assert_eq!(locate(p("/gas/superficial_velocity_m_s"), 1, &pts[1]).path, "/grid/0/values/1");
        assert_eq!(locate(p("/dem/time_step_s"), 1, &pts[1]).path, "/base/dem/time_step_s");
        assert!(locate(p("/dem/time_step_s"), 1, &pts[1])
            .message
            .starts_with("point 1 (superficial_velocity_m_s=-1.0)"));
    }

    #[test]
    fn the_summary_is_the_mean_and_deviation_over_the_second_half() {
        let case: Case = serde_json::from_value(json!({
            "name": "s", "column": {"diameter_m": 0.02, "height_m": 0.1},
            "particles": {"diameter_m": 0.001, "density_kg_m3": 1000.0, "youngs_modulus_pa": 1e7, "poisson_ratio": 0.3,
                "sliding_friction": 0.1, "normal_damping": {"tsuji_alpha": 0.02}, "tangential_damping": {"tsuji_alpha": 0.0}},
            "bed": {"generated": {"settled_height_m": 0.02, "seed": 1}},
            "dem": {"time_step_s": 1e-6}, "end_time_s": 1.0,
            "gas": {"superficial_velocity_m_s": 0.5},
        }))
        .unwrap();
        // ΔP alternates 90/110 Pa from t = 0.5 on: mean 100, deviation 10; earlier samples are left out.
        let infos: Vec<SnapshotInfo> = (0..=10)
            .map(|n| SnapshotInfo {
                n,
                time_s: n as f64 / 10.0,
                step: n * 1000,
                pressure_drop_pa: Some(if n < 5 {
                    0.0
                } else if n % 2 == 0 {
                    90.0
                } else {
                    110.0
                }),
                mean_particle_height_m: Some(0.01),
            })
            .collect();
        let s = summarize(&case, &infos);
        assert_eq!(s.samples, 6);
        assert!((s.pressure_drop_mean_pa.unwrap() - 100.0).abs() < 1e-9);
        assert!((s.pressure_drop_std_pa.unwrap() - 10.0).abs() < 1e-9);
        assert_eq!(s.superficial_velocity_m_s, Some(0.5));
        assert_eq!((s.from_s, s.to_s), (0.5, 1.0));
    }
}
