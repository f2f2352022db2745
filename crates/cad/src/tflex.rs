//! T-FLEX nesting projects (stub).
