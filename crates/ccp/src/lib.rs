//! cutroute-ccp (being written).
