//! Grids: geometry and connectivity only.
