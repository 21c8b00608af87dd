//! A throwaway PostgreSQL cluster for a test: initdb in a temporary folder, a server on a free
//! loopback port (trust authentication, no other listener), one database; stopped and removed on
//! drop. As root the server runs as the `postgres` user (PostgreSQL refuses root).

use std::path::{Path, PathBuf};
use std::process::Command;

pub struct PgCluster {
    bin: PathBuf,
    dir: super::TempDir,
    pub port: u16,
}

/// The folder of initdb, pg_ctl and createdb: Debian's newest, or the PATH's.
fn pg_bin() -> Option<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir("/usr/lib/postgresql")
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path().join("bin"))
        .filter(|b| b.join("initdb").is_file() && b.join("pg_ctl").is_file())
        .collect();
    found.sort_by_key(|p| p.parent().and_then(|v| v.file_name()?.to_str()?.parse::<u32>().ok()).unwrap_or(0));
    if let Some(b) = found.pop() {
        return Some(b);
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).find(|d| d.join("initdb").is_file() && d.join("pg_ctl").is_file())
}

fn is_root() -> bool {
    Command::new("id").arg("-u").output().map(|o| o.stdout.starts_with(b"0\n")).unwrap_or(false)
}

/// Run a command line as the server's user; its error output on failure.
fn as_pg_user(line: &str) -> Result<(), String> {
    let out = if is_root() {
        Command::new("su").args(["postgres", "-s", "/bin/sh", "-c", line]).output()
    } else {
        Command::new("sh").args(["-c", line]).output()
    }
    .map_err(|e| format!("cannot run `{line}`: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!("`{line}` failed: {}", String::from_utf8_lossy(&out.stderr).trim()))
    }
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr()).map(|a| a.port()).expect("a free port")
}

impl PgCluster {
    /// Start a cluster with database `fluidbed`; Err says why PostgreSQL is not to be had here.
    pub fn start() -> Result<PgCluster, String> {
        let bin = pg_bin().ok_or("no initdb found (/usr/lib/postgresql/*/bin or PATH): apt-get install postgresql")?;
        let dir = super::TempDir::new("pg");
        let data = dir.path().join("pg");
        std::fs::create_dir(&data).map_err(|e| format!("cannot create {}: {e}", data.display()))?;
        if is_root() {
            let _ = Command::new("chmod").arg("755").arg(dir.path()).status();
            let _ = Command::new("chown").args(["postgres"]).arg(&data).status();
        }
        let port = free_port();
        let q = |p: &Path| p.display().to_string();
        as_pg_user(&format!("{} -D {} -A trust -U postgres >/dev/null", q(&bin.join("initdb")), q(&data)))?;
        let cluster = PgCluster { bin: bin.clone(), dir, port };
        as_pg_user(&format!(
            "{} -D {d} -l {d}/log -o '-p {port} -k {d} -c listen_addresses=127.0.0.1' -w start >/dev/null",
            q(&bin.join("pg_ctl")),
            d = q(&data)
        ))?;
        as_pg_user(&format!("{} -h 127.0.0.1 -p {port} -U postgres fluidbed", q(&bin.join("createdb"))))?;
        Ok(cluster)
    }

    pub fn url(&self) -> String {
        format!("postgres://postgres@127.0.0.1:{}/fluidbed", self.port)
    }
}

impl Drop for PgCluster {
    fn drop(&mut self) {
        let data = self.dir.path().join("pg");
        let _ = as_pg_user(&format!(
            "{} -D {} -m immediate stop >/dev/null 2>&1",
            self.bin.join("pg_ctl").display(),
            data.display()
        ));
    }
}
