"""Material-point (MPM) scenes and post-processing: the thesis ch. 4 wedge hopper, discharge rate."""
