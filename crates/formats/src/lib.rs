//! cutroute-formats (being written).
