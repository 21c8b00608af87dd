//! fluidbed-server: the HTTP service (see issue 3).
