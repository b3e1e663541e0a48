//! The branch as CSV, its events as JSON, and its response curves as PNG.
