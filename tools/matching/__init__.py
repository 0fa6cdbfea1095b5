"""Feature matching and its evaluation (thesis 7.2-7.3): sparse corner matching, dense baseline, metrics,
adaptive thresholds."""
