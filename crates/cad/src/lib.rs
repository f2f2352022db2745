//! cutroute-cad (being written).
