"""Calibration: the free-motion observer (Eq. 15) and the payload at rest, the joints' Eq. 1,
T_e of the frequency model (Section 5.1) with an effective tip mass, and the F/T sensor's
cross-talk into the lateral forces."""
