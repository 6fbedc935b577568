"""Surrogates: the paper's kernel density of the merits (`kernel_density`), the Gaussian process beside it
(`gaussian_process`, with BoTorch), dynamic descriptors (`descriptors`) and the per-ask choice between the regression
models (`choice`). The acquisitions built on them, and the failure model, are in `acquisition/`; nothing here imports
from there.

A regression surrogate offers ``leave_one_out()`` (held-out predictions of the merits, by which `auto` ranks them)
and an acquisition function the optimizers minimize (`acquisition.AcquisitionFunction`)."""
