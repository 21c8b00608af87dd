//! A headless Chromium driven over WebDriver (chromedriver, plain HTTP): enough for the live
//! page's test — open a URL, run a script, wait for a condition, read the console log, take a
//! screenshot.

use base64::Engine;
use serde_json::{json, Value};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// One browser session and the chromedriver behind it (both ended on drop).
pub struct Browser {
    http: reqwest::Client,
    session: String,
    driver: Child,
}

fn on_path(names: &[&str]) -> Option<String> {
    let path = std::env::var_os("PATH")?;
    names.iter().find_map(|n| {
        std::env::split_paths(&path).map(|d| d.join(n)).find(|p| p.is_file()).map(|p| p.display().to_string())
    })
}

impl Browser {
    /// Start chromedriver on a free port and a headless Chromium session of `width`×`height`;
    /// Err(why) if chromium or chromedriver is not installed.
    pub async fn start(width: u32, height: u32) -> Result<Browser, String> {
        let chrome = on_path(&["chromium", "chromium-browser", "google-chrome"])
            .ok_or("no chromium on PATH (apt-get install chromium chromium-driver)")?;
        let driver_bin =
            on_path(&["chromedriver"]).ok_or("no chromedriver on PATH (apt-get install chromium-driver)")?;
        let port = std::net::TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr()).expect("free port").port();
        let driver = Command::new(&driver_bin)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| format!("cannot start {driver_bin}: {e}"))?;
        let http = reqwest::Client::new();
        let base = format!("http://127.0.0.1:{port}");
        let t0 = Instant::now();
        let mut b = Browser { http, session: String::new(), driver };
        while b.http.get(format!("{base}/status")).send().await.is_err() {
            if t0.elapsed() > Duration::from_secs(20) {
                return Err(format!("{driver_bin} did not answer on port {port} within 20 s"));
            }
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": chrome, "args": [
                "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                format!("--window-size={width},{height}")]},
            "goog:loggingPrefs": {"browser": "ALL"}
        }}});
        let r: Value = b
            .http
            .post(format!("{base}/session"))
            .json(&caps)
            .send()
            .await
            .map_err(|e| e.to_string())?
            .json()
            .await
            .map_err(|e| e.to_string())?;
        let id = r["value"]["sessionId"].as_str().ok_or_else(|| format!("no browser session: {r}"))?;
        b.session = format!("{base}/session/{id}");
        Ok(b)
    }

    async fn call(&self, method: reqwest::Method, path: &str, body: Value) -> Value {
        let mut req = self.http.request(method, format!("{}/{path}", self.session));
        if !body.is_null() {
            req = req.json(&body);
        }
        let r: Value = req.send().await.expect("webdriver call").json().await.expect("webdriver json");
        assert!(r["value"].get("error").is_none(), "webdriver {path}: {}", r["value"]);
        r["value"].clone()
    }

    pub async fn goto(&self, url: &str) {
        self.call(reqwest::Method::POST, "url", json!({ "url": url })).await;
    }

    /// Run `script` (a function body; `return` gives the value) in the page.
    pub async fn eval(&self, script: &str) -> Value {
        self.call(reqwest::Method::POST, "execute/sync", json!({ "script": script, "args": [] })).await
    }

    /// Poll `script` until it returns something other than null/false (its value), or None
    /// after `timeout`.
    pub async fn wait_for(&self, script: &str, timeout: Duration) -> Option<Value> {
        let t0 = Instant::now();
        while t0.elapsed() < timeout {
            let v = self.eval(script).await;
            if !(v.is_null() || v == Value::Bool(false)) {
                return Some(v);
            }
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
        None
    }

    /// The browser's console and network log since the last call (each `{level, message, source}`).
    pub async fn log(&self) -> Vec<Value> {
        let v = self.call(reqwest::Method::POST, "se/log", json!({ "type": "browser" })).await;
        v.as_array().cloned().unwrap_or_default()
    }

    /// A PNG of the window.
    pub async fn screenshot(&self) -> Vec<u8> {
        let v = self.call(reqwest::Method::GET, "screenshot", Value::Null).await;
        base64::engine::general_purpose::STANDARD.decode(v.as_str().unwrap_or("")).expect("screenshot base64")
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            // Blocking on drop: a short, best-effort end of the session before chromedriver goes.
            let url = self.session.clone();
            let _ = std::thread::spawn(move || {
                let rt = tokio::runtime::Builder::new_current_thread().enable_all().build();
                if let Ok(rt) = rt {
                    rt.block_on(async { reqwest::Client::new().delete(url).send().await.ok() });
                }
            })
            .join();
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}
