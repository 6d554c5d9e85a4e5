"""Drawing with matplotlib: the only package that imports it, always lazily, inside functions."""
