-- Sweeps: a name and the points, as JSON [{"job": id, "set": {pointer: value}}], in order.
CREATE TABLE IF NOT EXISTS sweeps (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT UNIQUE NOT NULL,
  name TEXT NOT NULL,
  created_at TEXT NOT NULL,
  points TEXT NOT NULL
);
