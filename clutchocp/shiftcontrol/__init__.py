"""Shift control: slip feedback along the optimal engagement and its Monte Carlo proof (clutchocp robust)."""
