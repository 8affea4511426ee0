"""The 2-DOF sensing-antenna simulator: it models the device and writes recordings."""
