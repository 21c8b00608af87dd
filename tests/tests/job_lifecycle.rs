//! Submit a small DEM case, follow the event stream to the end, fetch every format and check the
//! contents numerically.

use fluidbed_core::output::npy;
use fluidbed_tests::*;
use serde_json::Value;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn submitted_case_streams_events_and_every_download_checks_out() {
    let dir = TempDir::new("lifecycle");
    let server = start(dir.path(), None);
    let base = server.url();
    let http = reqwest::Client::new();
    let (nx, layers) = (6, 4);
    let n_particles = nx * nx * layers;
    let case = lattice_case(nx, layers, 0.02, 0.005);

    let resp = http.post(format!("{base}/v1/jobs")).json(&case).send().await.unwrap();
    assert_eq!(resp.status(), 201);
    let loc = resp.headers()["location"].to_str().unwrap().to_string();
    let job: Value = resp.json().await.unwrap();
    assert_eq!(loc, format!("/v1/jobs/{}", job["id"].as_str().unwrap()));
    assert!(matches!(job["status"].as_str(), Some("queued" | "running")));
    let url = format!("{base}{loc}");

    // The stream ends by itself after the final event.
    let events = read_events(&http, &url, None).await;
    let last = events.last().expect("events");
    assert_eq!(last.event, "end");
    let end: Value = serde_json::from_str(&last.data).unwrap();
    assert_eq!(end["status"], "succeeded", "{end}");
    let snaps: Vec<&SseEvent> = events.iter().filter(|e| e.event == "snapshot").collect();
    // 0.02 s every 0.005 s: the initial state and four more.
    assert_eq!(snaps.len(), 5);
    for (n, e) in snaps.iter().enumerate() {
        assert_eq!(e.id.as_deref(), Some(n.to_string().as_str()), "snapshot events carry their number as id");
        let d: Value = serde_json::from_str(&e.data).unwrap();
        assert_eq!(d["n"], n as u64);
        let eps = d["voidage"].as_array().expect("voidage in the event");
        assert_eq!(eps.len(), d["nz"].as_u64().unwrap() as usize * d["cells_per_layer"].as_u64().unwrap() as usize);
    }

    // A late client resuming after snapshot 2 gets 3 and 4, then the end.
    let resumed = read_events(&http, &url, Some("2")).await;
    let ids: Vec<_> = resumed.iter().filter(|e| e.event == "snapshot").filter_map(|e| e.id.clone()).collect();
    assert_eq!(ids, ["3", "4"]);
    assert_eq!(resumed.last().unwrap().event, "end");

    let job: Value = http.get(&url).send().await.unwrap().json().await.unwrap();
    assert_eq!(job["status"], "succeeded");
    assert_eq!(job["progress"], 1.0);
    assert!((job["time_s"].as_f64().unwrap() - 0.02).abs() < 1e-12);
    assert!(job["steps"].as_u64().unwrap() > 0 && job["plan"].is_object());
    // The plan says what is skipped and why; the status has the wall time of each stage.
    let skipped: Vec<&str> = job["plan"]["skipped"].as_array().unwrap().iter().filter_map(Value::as_str).collect();
    assert!(skipped.contains(&"gas solver: the case has no gas section"), "{skipped:?}");
    let stages = &job["stage_seconds"];
    assert!(stages["contacts_integration"].as_f64().unwrap() > 0.0, "{stages}");
    assert_eq!(stages["gas"].as_f64(), Some(0.0), "{stages}");

    let list: Value = http.get(format!("{url}/snapshots")).send().await.unwrap().json().await.unwrap();
    let list = list["snapshots"].as_array().unwrap().clone();
    assert_eq!(list.len(), 5);

    let vp = std::f64::consts::PI * D.powi(3) / 6.0;
    for s in &list {
        let n = s["n"].as_u64().unwrap();
        // npy voidage: [nz, cells_per_layer], ε in [0, 1], Σ(1 − ε)·V_cell = N·V_p (direct method, paper eq. 2).
        let bytes = http.get(format!("{url}/snapshots/{n}?format=npy")).send().await.unwrap().bytes().await.unwrap();
        let (shape, eps) = npy::decode_f64(&bytes).expect("valid npy");
        assert_eq!(shape.len(), 2);
        assert!(eps.iter().all(|e| (0.0..=1.0).contains(e)), "voidage within [0, 1]");
        let js: Value =
            http.get(format!("{url}/snapshots/{n}?format=json")).send().await.unwrap().json().await.unwrap();
        let vc = js["grid"]["cell_volume_m3"].as_f64().unwrap();
        assert_eq!(shape[0] * shape[1], js["grid"]["num_cells"].as_u64().unwrap() as usize);
        let solid: f64 = eps.iter().map(|e| (1.0 - e) * vc).sum();
        let expect = n_particles as f64 * vp;
        assert!((solid - expect).abs() < 1e-9 * expect, "solid volume {solid} vs N·V_p {expect}");
        assert_eq!(js["particles"]["positions_m"].as_array().unwrap().len(), n_particles);
        assert!((js["time_s"].as_f64().unwrap() - s["time_s"].as_f64().unwrap()).abs() < 1e-15);

        let vtk = http.get(format!("{url}/snapshots/{n}?format=vtk")).send().await.unwrap().text().await.unwrap();
        assert!(vtk.starts_with("# vtk DataFile") && vtk.contains("DATASET UNSTRUCTURED_GRID"));
        assert!(vtk.contains("SCALARS voidage double 1"));
        let pv = http
            .get(format!("{url}/snapshots/{n}?format=vtk&what=particles"))
            .send()
            .await
            .unwrap()
            .text()
            .await
            .unwrap();
        assert!(pv.contains(&format!("POINTS {n_particles} double")) && pv.contains("VECTORS velocity_m_s double"));
        let pn = http
            .get(format!("{url}/snapshots/{n}?format=npy&field=particles"))
            .send()
            .await
            .unwrap()
            .bytes()
            .await
            .unwrap();
        assert_eq!(npy::decode_f64(&pn).unwrap().0, vec![n_particles, 6]);
    }

    // The ΔP series has one row per snapshot (empty ΔP without gas).
    let csv = http.get(format!("{url}/pressure-drop?format=csv")).send().await.unwrap().text().await.unwrap();
    let mut lines = csv.lines();
    assert!(lines.next().unwrap().starts_with("time_s,pressure_drop_pa"));
    assert_eq!(lines.count(), list.len());
    let pj: Value = http.get(format!("{url}/pressure-drop?format=json")).send().await.unwrap().json().await.unwrap();
    assert_eq!(pj["time_s"].as_array().unwrap().len(), list.len());
    let png = http.get(format!("{url}/snapshots/4?format=png")).send().await.unwrap().bytes().await.unwrap();
    let png = Picture::decode(&png);
    assert!(png.width >= 400 && png.colours() > 20, "a voidage figure: {}×{}", png.width, png.height);

    for path in ["/v1/schema/case", "/openapi.json", "/healthz"] {
        let r = http.get(format!("{base}{path}")).send().await.unwrap();
        assert_eq!(r.status(), 200, "{path}");
        let _: Value = r.json().await.expect("JSON document");
    }
    server.shutdown();
}
