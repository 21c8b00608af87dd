//! A small typed client for the fluidbed HTTP API.

use anyhow::{anyhow, Result};
use reqwest::{header, Client, StatusCode};
use serde_json::Value;

/// An error the CLI maps to an exit code.
#[derive(Debug)]
pub enum ApiError {
    /// 422: the case was refused; the problem document lists each field.
    Invalid(Value),
    /// Anything else: connection failures, 4xx/5xx answers.
    Server(String),
}

impl std::fmt::Display for ApiError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ApiError::Invalid(p) => write!(f, "invalid case: {}", p["detail"].as_str().unwrap_or("")),
            ApiError::Server(m) => write!(f, "{m}"),
        }
    }
}
impl std::error::Error for ApiError {}

#[derive(Clone)]
pub struct Api {
    pub base: String,
    pub http: Client,
}

impl Api {
    pub fn new(base: &str, token: Option<&str>) -> Result<Api> {
        let mut headers = header::HeaderMap::new();
        if let Some(t) = token {
            headers.insert(header::AUTHORIZATION, header::HeaderValue::from_str(&format!("Bearer {t}"))?);
        }
        let http = Client::builder().default_headers(headers).build()?;
        Ok(Api { base: base.trim_end_matches('/').to_string(), http })
    }

    pub fn url(&self, path: &str) -> String {
        format!("{}{}", self.base, path)
    }

    async fn check(resp: reqwest::Result<reqwest::Response>) -> Result<reqwest::Response, ApiError> {
        let resp = resp.map_err(|e| ApiError::Server(format!("cannot reach the server: {e}")))?;
        let status = resp.status();
        if status.is_success() {
            return Ok(resp);
        }
        let body: Value = resp.json().await.unwrap_or(Value::Null);
        if status == StatusCode::UNPROCESSABLE_ENTITY {
            return Err(ApiError::Invalid(body));
        }
        let detail = body["detail"].as_str().unwrap_or("").to_string();
        Err(ApiError::Server(format!("server answered {status}: {} {detail}", body["title"].as_str().unwrap_or(""))))
    }

    pub async fn get_json(&self, path: &str) -> Result<Value, ApiError> {
        let r = Self::check(self.http.get(self.url(path)).send().await).await?;
        r.json().await.map_err(|e| ApiError::Server(format!("bad JSON from server: {e}")))
    }

    /// GET raw bytes; Ok(None) on 404.
    pub async fn get_bytes(&self, path: &str) -> Result<Option<Vec<u8>>, ApiError> {
        let r = self.http.get(self.url(path)).send().await;
        if let Ok(resp) = &r {
            if resp.status() == StatusCode::NOT_FOUND {
                return Ok(None);
            }
        }
        let r = Self::check(r).await?;
        r.bytes().await.map(|b| Some(b.to_vec())).map_err(|e| ApiError::Server(format!("download failed: {e}")))
    }

    /// Submit a case (JSON text); the created job.
    pub async fn submit(&self, case_json: &str) -> Result<Value, ApiError> {
        let r = self
            .http
            .post(self.url("/v1/jobs"))
            .header(header::CONTENT_TYPE, "application/json")
            .body(case_json.to_string())
            .send()
            .await;
        let r = Self::check(r).await?;
        r.json().await.map_err(|e| ApiError::Server(format!("bad JSON from server: {e}")))
    }

    pub async fn cancel(&self, id: &str) -> Result<Value, ApiError> {
        let r = Self::check(self.http.delete(self.url(&format!("/v1/jobs/{id}"))).send().await).await?;
        r.json().await.map_err(|e| ApiError::Server(format!("bad JSON from server: {e}")))
    }

    pub async fn wait_healthy(&self) -> Result<()> {
        for _ in 0..100 {
            if let Ok(r) = self.http.get(self.url("/healthz")).send().await {
                if r.status().is_success() {
                    return Ok(());
                }
            }
            tokio::time::sleep(std::time::Duration::from_millis(100)).await;
        }
        Err(anyhow!("server at {} does not answer /healthz", self.base))
    }
}
