"""Bring-up of the whole stack: runner, launch file, mission, bag tools, plots."""
