//! The co-simulation master (see issue 3).
