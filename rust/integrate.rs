//! Native integrators (work in progress).
