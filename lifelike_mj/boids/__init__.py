"""Heterogeneous boids of Nakamura 2013: engine, measures and classifier, presets, MuJoCo scene."""
