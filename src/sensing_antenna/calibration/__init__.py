"""Calibration: the free-motion observer (Eq. 15) and T_e of the frequency model (Section 5.1)."""
