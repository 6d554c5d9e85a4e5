"""Fuzzy logic itself: membership shapes, hedges, norms, the neuron, operator settings."""
