"""Physical models of the DUKW-Ling shared by the simulator, the estimator and the tools."""
