"""The step: an ordered list of named stages, the only place that sequences kernels."""
