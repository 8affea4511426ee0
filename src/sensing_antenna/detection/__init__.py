"""What the head's controller and the estimators both run online on the sensor samples.

- :mod:`.filters`: the free-motion observer of Eq. 15 and the low-pass filter of Eq. 20;
- :mod:`.contact`: the contact residual of Eq. 16 and the contact instant t_c (Section 4.2);
- :mod:`.push`: the push criterion that stops the motors (Section 4, step 4).

This floor sits below both the device simulator (whose controller stops on the push criterion)
and the estimation pipeline (whose front end finds t_c and t_1 with the same detectors).
"""
