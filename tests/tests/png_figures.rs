//! The PNG figures as a researcher downloads them: a snapshot's voidage and gauge pressure on the
//! axial plane, and the pressure-drop trace, decoded and checked for their size, a title, a colour
//! bar spanning the colour map, and content (not a blank or one-colour picture). With
//! FLUIDBED_KEEP_PNGS=dir the three files are kept there to look at.

use fluidbed_core::output::plot::colour;
use fluidbed_tests::*;
use serde_json::json;
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn snapshot_and_trace_pngs_are_labelled_figures() {
    let dir = TempDir::new("png");
    let server = start(dir.path(), None);
    let http = reqwest::Client::new();
    let mut case = lattice_case(3, 1, 0.002, 0.001);
    case["name"] = json!("png figures");
    case["gas"] = json!({ "superficial_velocity_m_s": 0.3, "ramp_time_s": 0.0 });
    case["outputs"]["fields"] = json!(["voidage", "pressure"]);
    let r = http.post(format!("{}/v1/jobs", server.url())).json(&case).send().await.unwrap();
    assert_eq!(r.status(), 201);
    let url = format!("{}{}", server.url(), r.headers()["location"].to_str().unwrap());
    assert_eq!(wait_final(&http, &url, Duration::from_secs(120)).await["status"], "succeeded");

    let keep = std::env::var_os("FLUIDBED_KEEP_PNGS").map(std::path::PathBuf::from);
    let get = |path: String, file: &'static str| fetch_png(http.clone(), path, keep.clone().map(|d| d.join(file)));
    let voidage = get(format!("{url}/snapshots/2?format=png"), "voidage.png").await;
    let pressure = get(format!("{url}/snapshots/2?format=png&field=pressure"), "pressure.png").await;
    let trace = get(format!("{url}/pressure-drop?format=png"), "pressure_drop.png").await;

    for (name, p) in [("voidage", &voidage), ("pressure", &pressure)] {
        // a 44 × 44 mm column: a square plot with its axes, title and colour bar beside it
        assert!((400..=700).contains(&p.width) && (250..=600).contains(&p.height), "{name}: {}×{}", p.width, p.height);
        assert!(p.colours() > 50 && p.inked() > 0.2, "{name}: {} colours, {:.2} inked", p.colours(), p.inked());
        assert!(p.dark_in_rows(0..40) > 100, "{name}: a title");
        // the colour bar runs through the whole map, low end to high end
        for t in [0.0, 0.5, 1.0] {
            assert!(p.rgb.contains(&colour(t)), "{name}: the colour bar holds colour({t})");
        }
    }
    assert_ne!(voidage.rgb, pressure.rgb, "pressure and voidage are different pictures");
    assert_eq!((trace.width, trace.height), (800, 480));
    assert!(trace.colours() > 20 && trace.inked() > 0.05, "trace: {} colours", trace.colours());
    assert!(trace.dark_in_rows(0..40) > 100, "trace: a title");
    assert!(trace.dark_in_rows(440..480) > 50, "trace: the time axis's title");
    server.shutdown();
}

/// GET a PNG (kept at `keep` when given) and decode it.
async fn fetch_png(http: reqwest::Client, url: String, keep: Option<std::path::PathBuf>) -> Picture {
    let r = http.get(url).send().await.unwrap();
    assert_eq!(r.status(), 200);
    assert_eq!(r.headers()["content-type"], "image/png");
    let bytes = r.bytes().await.unwrap().to_vec();
    if let Some(path) = keep {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, &bytes).unwrap();
    }
    Picture::decode(&bytes)
}
