//! Numerics, in one home. Nothing here knows the model: slices, banded and dense matrices.
//!
//! * `dense`: the dot product of the kernels, the 3x3 Cholesky of the floating-frame blocks,
//!   the dense Cholesky and triangular solves, the pseudoinverse solve of the state correction;
//! * `banded`: band storage, the banded Cholesky (constant FFRF and ANCF mass factors, the
//!   Gram matrix of the sparse UK path) with its selected inverse and an inertia count;
//! * `envelope`: envelope (profile) storage, its Cholesky factor and selected inverse (the
//!   Gram matrix of the spatial UK path); `block_tridiag`: the same factor by fixed-size
//!   blocks where that envelope is block tridiagonal with small blocks;
//! * `band_lu`: the band LU with partial pivoting of the implicit methods' sparse Newton
//!   matrices, real and complex; `static_lu`: their sparse LU with a fill-reducing order and
//!   kept pivots (a wide band whose elimination stays sparse); `lu`: their dense LU;
//! * `small_svd`: the QR + one-sided Jacobi SVD of the UK pseudoinverse;
//! * `rcm`: the reverse Cuthill-McKee order that makes the sparse matrices banded;
//! * `simd_state`: the vector registers' upper halves cleared after faer's decompositions and
//!   before a run (faer's AVX kernels can leave them in use, which slows the SSE kernels 2x);
//! * `quadrature`: the Gauss rule of the element integrals;
//! * `dual`: forward-mode dual and hyper-dual numbers (exact gradients and Hessians of small
//!   generic energies: the 3D beam element).
//!
//! Everything is allocation free after construction except `dense::pinv_solve` (faer's SVD,
//! not on a per-step path).

pub mod band_lu;
pub mod banded;
pub mod block_tridiag;
pub mod dense;
pub mod dual;
pub mod envelope;
pub mod lu;
pub mod lu_rows;
pub mod quadrature;
pub mod rcm;
pub mod simd_state;
pub mod rot3;
pub mod small_svd;
pub mod static_lu;

pub use banded::{Banded, BandedCholesky};
pub use dense::{cholesky3, dot4, solve_lower3, solve_upper3};
pub use quadrature::GAUSS4;
