"""Figures of the papers' experiments, side by side with the papers' numbers (matplotlib)."""
