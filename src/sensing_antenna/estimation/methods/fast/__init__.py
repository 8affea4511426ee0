"""The ``fast`` method: parametric window fits declared as soon as the estimate is sure."""
