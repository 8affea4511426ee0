"""The paper's method: Estimator 1 (spectral omega_1), fusion with Estimator 2, Section 4."""
