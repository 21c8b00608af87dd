-- Wall seconds per stage of a running job (JSON), since it last (re)started.
ALTER TABLE jobs ADD COLUMN stage_seconds TEXT;
