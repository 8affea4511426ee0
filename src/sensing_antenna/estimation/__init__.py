"""Contact-point estimation: contact instant, push, Estimators 1 and 2, fusion, baselines."""
