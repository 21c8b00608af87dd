//! A small typed client for the fluidbed HTTP API: requests and answers are fluidbed-api's
//! types, the same ones the server serves.

use anyhow::{anyhow, Result};
use fluidbed_api::{Job, JobList, ListQuery, Problem, SnapshotList, Sweep, SweepRequest};
use reqwest::{header, Client, StatusCode};
use serde::de::DeserializeOwned;
use serde::Serialize;

/// For a request without a query string.
pub const NO_QUERY: &[(&str, &str); 0] = &[];

/// An error the CLI maps to an exit code.
#[derive(Debug)]
pub enum ApiError {
    /// 422: the case was refused; the problem document lists each field.
    Invalid(Box<Problem>),
    /// Anything else: connection failures, 4xx/5xx answers.
    Server(String),
}

impl std::fmt::Display for ApiError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ApiError::Invalid(p) => write!(f, "invalid case: {}", p.detail),
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
        let text = resp.text().await.unwrap_or_default();
        let problem: Option<Problem> = serde_json::from_str(&text).ok();
        match problem {
            Some(p) if status == StatusCode::UNPROCESSABLE_ENTITY => Err(ApiError::Invalid(Box::new(p))),
            Some(p) => Err(ApiError::Server(format!("server answered {status}: {} {}", p.title, p.detail))),
            None => Err(ApiError::Server(format!("server answered {status}: {}", text.trim()))),
        }
    }

    async fn json<T: DeserializeOwned>(resp: reqwest::Response) -> Result<T, ApiError> {
        resp.json().await.map_err(|e| ApiError::Server(format!("unexpected answer from the server: {e}")))
    }

    /// GET a JSON document as `T`.
    pub async fn get<T: DeserializeOwned>(&self, path: &str, query: &impl Serialize) -> Result<T, ApiError> {
        Self::json(Self::check(self.http.get(self.url(path)).query(query).send().await).await?).await
    }

    pub async fn job(&self, id: &str) -> Result<Job, ApiError> {
        self.get(&format!("/v1/jobs/{id}"), NO_QUERY).await
    }

    pub async fn jobs(&self, query: &ListQuery) -> Result<JobList, ApiError> {
        self.get("/v1/jobs", query).await
    }

    pub async fn snapshots(&self, id: &str) -> Result<SnapshotList, ApiError> {
        self.get(&format!("/v1/jobs/{id}/snapshots"), NO_QUERY).await
    }

    /// GET raw bytes; Ok(None) on 404.
    pub async fn get_bytes(&self, path: &str, query: &impl Serialize) -> Result<Option<Vec<u8>>, ApiError> {
        let r = self.http.get(self.url(path)).query(query).send().await;
        if let Ok(resp) = &r {
            if resp.status() == StatusCode::NOT_FOUND {
                return Ok(None);
            }
        }
        let r = Self::check(r).await?;
        r.bytes().await.map(|b| Some(b.to_vec())).map_err(|e| ApiError::Server(format!("download failed: {e}")))
    }

    /// Submit a case (JSON text, sent as written so that the server sees any key given twice).
    pub async fn submit(&self, case_json: &str) -> Result<Job, ApiError> {
        let r = self
            .http
            .post(self.url("/v1/jobs"))
            .header(header::CONTENT_TYPE, "application/json")
            .body(case_json.to_string())
            .send()
            .await;
        Self::json(Self::check(r).await?).await
    }

    /// Submit a sweep (one job per point).
    pub async fn submit_sweep(&self, req: &SweepRequest) -> Result<Sweep, ApiError> {
        Self::json(Self::check(self.http.post(self.url("/v1/sweeps")).json(req).send().await).await?).await
    }

    pub async fn sweep(&self, id: &str) -> Result<Sweep, ApiError> {
        self.get(&format!("/v1/sweeps/{id}"), NO_QUERY).await
    }

    pub async fn cancel(&self, id: &str) -> Result<Job, ApiError> {
        Self::json(Self::check(self.http.delete(self.url(&format!("/v1/jobs/{id}"))).send().await).await?).await
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
