//! Module `eos`.
