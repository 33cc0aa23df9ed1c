"""Simulator of the DUKW-Ling on sand, in the surf and afloat, behind the drivers' topics."""
