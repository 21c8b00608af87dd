//! Follow a job's event stream to its end: a progress bar with ETA and the latest ΔP (or JSON
//! lines with `--json`). A dropped connection is resumed with Last-Event-ID.

use crate::api::{Api, ApiError};
use fluidbed_api::{JobStatus, ProgressEvent, SnapshotEvent, StatusEvent};
use futures_util::StreamExt;
use serde_json::Value;
use std::io::{IsTerminal, Write};

/// One parsed server-sent event.
#[derive(Debug, Default, Clone)]
pub struct SseEvent {
    pub event: String,
    pub id: Option<String>,
    pub data: String,
}

/// Split complete events off the front of `buf` (events end with a blank line).
pub fn parse_events(buf: &mut String) -> Vec<SseEvent> {
    let mut out = Vec::new();
    while let Some(end) = buf.find("\n\n") {
        let block: String = buf.drain(..end + 2).collect();
        let mut ev = SseEvent::default();
        let mut data = Vec::new();
        for line in block.lines() {
            if let Some(v) = line.strip_prefix("data:") {
                data.push(v.strip_prefix(' ').unwrap_or(v).to_string());
            } else if let Some(v) = line.strip_prefix("event:") {
                ev.event = v.trim().to_string();
            } else if let Some(v) = line.strip_prefix("id:") {
                ev.id = Some(v.trim().to_string());
            }
        }
        if !data.is_empty() || !ev.event.is_empty() {
            ev.data = data.join("\n");
            out.push(ev);
        }
    }
    out
}

/// The final status (succeeded, failed, cancelled) and message.
pub struct Outcome {
    pub status: JobStatus,
    pub message: Option<String>,
}

/// Watch until the `end` event; `json` prints each event as a JSON line instead of a bar.
pub async fn watch(api: &Api, id: &str, json: bool) -> Result<Outcome, ApiError> {
    let mut last_id: Option<String> = None;
    let mut bar = Bar::new(!json);
    let mut failures = 0;
    loop {
        let mut req = api.http.get(api.url(&format!("/v1/jobs/{id}/events")));
        if let Some(l) = &last_id {
            req = req.header("Last-Event-ID", l.as_str());
        }
        let resp = match req.send().await {
            Ok(r) if r.status().is_success() => r,
            Ok(r) => return Err(ApiError::Server(format!("event stream answered {}", r.status()))),
            Err(e) => {
                failures += 1;
                if failures > 20 {
                    return Err(ApiError::Server(format!("lost the event stream: {e}")));
                }
                tokio::time::sleep(std::time::Duration::from_millis(500)).await;
                continue;
            }
        };
        let mut stream = resp.bytes_stream();
        let mut buf = String::new();
        while let Some(chunk) = stream.next().await {
            let Ok(chunk) = chunk else { break };
            buf.push_str(&String::from_utf8_lossy(&chunk).replace("\r\n", "\n"));
            for ev in parse_events(&mut buf) {
                failures = 0;
                if ev.id.is_some() {
                    last_id = ev.id.clone();
                }
                if json {
                    let data: Value = serde_json::from_str(&ev.data).unwrap_or(Value::Null);
                    let mut line = serde_json::json!({ "event": ev.event, "id": ev.id, "data": data });
                    if ev.event == "snapshot" {
                        // Fields are long; scripts fetch them. Keep the scalars.
                        for k in ["voidage", "pressure_pa", "layer_pressure_drop_pa", "grid"] {
                            line["data"].as_object_mut().map(|o| o.remove(k));
                        }
                    }
                    println!("{line}");
                } else {
                    bar.update(&ev);
                }
                if ev.event == "end" {
                    bar.finish();
                    let end: StatusEvent = serde_json::from_str(&ev.data)
                        .map_err(|e| ApiError::Server(format!("unexpected end event `{}`: {e}", ev.data)))?;
                    return Ok(Outcome { status: end.status, message: end.message });
                }
            }
        }
        // The stream closed before the end: resume where we were.
        failures += 1;
        if failures > 20 {
            return Err(ApiError::Server("the event stream keeps closing early".into()));
        }
        tokio::time::sleep(std::time::Duration::from_millis(300)).await;
    }
}

/// A one-line progress bar on stderr (a line per snapshot when stderr is not a terminal).
struct Bar {
    on: bool,
    tty: bool,
    dp: Option<f64>,
    height: Option<f64>,
}

impl Bar {
    fn new(on: bool) -> Bar {
        Bar { on, tty: std::io::stderr().is_terminal(), dp: None, height: None }
    }
    fn update(&mut self, ev: &SseEvent) {
        if !self.on {
            return;
        }
        match ev.event.as_str() {
            "snapshot" => {
                let Ok(d) = serde_json::from_str::<SnapshotEvent>(&ev.data) else { return };
                self.dp = d.pressure_drop_pa.or(self.dp);
                self.height = d.mean_particle_height_m.or(self.height);
                if !self.tty {
                    eprintln!("snapshot {} at t = {:.4} s{}", d.n, d.time_s, self.latest());
                }
            }
            "progress" if self.tty => {
                let Ok(d) = serde_json::from_str::<ProgressEvent>(&ev.data) else { return };
                let filled = ((d.progress * 30.0).round() as usize).min(30);
                let eta = d.eta_s.map(|e| format!("ETA {e:.0} s")).unwrap_or_else(|| "ETA ?".into());
                eprint!(
                    "\r[{}{}] {:5.1}%  t = {:.4}/{:.4} s  {eta}{}   ",
                    "#".repeat(filled),
                    " ".repeat(30 - filled),
                    100.0 * d.progress,
                    d.time_s,
                    d.end_time_s,
                    self.latest()
                );
                let _ = std::io::stderr().flush();
            }
            "status" => {
                let Ok(d) = serde_json::from_str::<StatusEvent>(&ev.data) else { return };
                let m = d.message.map(|m| format!(" — {m}")).unwrap_or_default();
                if self.tty {
                    if !m.is_empty() {
                        eprint!("\rstatus: {}{m}   ", d.status);
                        let _ = std::io::stderr().flush();
                    }
                } else {
                    eprintln!("status: {}{m}", d.status);
                }
            }
            _ => {}
        }
    }
    fn latest(&self) -> String {
        match (self.dp, self.height) {
            (Some(dp), _) => format!("  ΔP = {dp:.1} Pa"),
            (None, Some(h)) => format!("  mean particle height = {:.2} mm", 1e3 * h),
            _ => String::new(),
        }
    }
    fn finish(&mut self) {
        if self.on && self.tty {
            eprintln!();
        }
    }
}
