-- The node running a job and until when (Unix seconds, the database's clock) its lease holds.
ALTER TABLE jobs ADD COLUMN owner TEXT;
ALTER TABLE jobs ADD COLUMN lease_until DOUBLE PRECISION;
