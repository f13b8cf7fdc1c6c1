"""Shift control that survives the clutch it meets: slip feedback along the optimal engagement and its Monte Carlo proof."""
