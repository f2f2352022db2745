//! cutroute-engine (being written).
