"""The paper's constrained benchmark surfaces and a runner for campaigns on them."""
