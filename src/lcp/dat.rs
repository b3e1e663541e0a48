//! Siconos' dense `.dat` LCP format (placeholder: being written).
