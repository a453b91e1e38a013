//! Nodal least-squares gradients.
