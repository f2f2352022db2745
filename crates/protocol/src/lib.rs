//! cutroute-protocol (being written).
