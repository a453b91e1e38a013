//! Module `riemann`.
