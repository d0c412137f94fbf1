//! Eigenvalues of a symmetric 2 × 2 matrix in closed form, for the planar scatter matrices of
//! scan segments, local lines and whole scans.
//!
//! Not for: eigenvectors or larger matrices (nalgebra's `SymmetricEigen`).

/// The eigenvalues (smaller, larger) of the symmetric 2 × 2 matrix [[a, b], [b, c]]: the
/// mean of the diagonal ∓ the root.
pub(crate) fn symmetric2_eigenvalues(a: f64, b: f64, c: f64) -> (f64, f64) {
    let mean = 0.5 * (a + c);
    let root = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    (mean - root, mean + root)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigenvalues_by_hand() {
        // [[2, 1], [1, 2]]: 1 and 3. [[4, 0], [0, 1]]: 1 and 4.
        assert_eq!(symmetric2_eigenvalues(2.0, 1.0, 2.0), (1.0, 3.0));
        assert_eq!(symmetric2_eigenvalues(4.0, 0.0, 1.0), (1.0, 4.0));
    }
}
