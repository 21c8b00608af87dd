CREATE TABLE IF NOT EXISTS jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT UNIQUE NOT NULL,
  name TEXT NOT NULL,
  status TEXT NOT NULL,
  case_json TEXT NOT NULL,
  created_at TEXT NOT NULL,
  started_at TEXT,
  finished_at TEXT,
  time_s REAL NOT NULL DEFAULT 0,
  end_time_s REAL NOT NULL,
  steps INTEGER NOT NULL DEFAULT 0,
  wall_s REAL NOT NULL DEFAULT 0,
  eta_s REAL,
  message TEXT,
  warnings TEXT NOT NULL,
  plan TEXT,
  cancel_requested INTEGER NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS jobs_status ON jobs(status);
CREATE TABLE IF NOT EXISTS snapshots (
  job_id TEXT NOT NULL,
  n INTEGER NOT NULL,
  time_s REAL NOT NULL,
  step INTEGER NOT NULL,
  pressure_drop_pa REAL,
  mean_particle_height_m REAL,
  PRIMARY KEY (job_id, n)
);
