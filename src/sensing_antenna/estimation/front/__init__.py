"""The front end shared by every method: from samples to the evidence known at t_e."""
