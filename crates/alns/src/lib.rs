//! cutroute-alns (being written).
