//! Numerical quadrature: the converged references that tests and the curve integrators compare
//! against.
