"""Figures of a running stack, without ROS: CPU time of a process, sensor-to-command latency.

Used by benchmarks/bench_stack.py (which explains the pairing in full).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

CLOCK_TICKS = os.sysconf('SC_CLK_TCK')
#: a sensor message no command followed within this long counts as lost, s
PAIR_WINDOW_S = 0.1


def cpu_seconds(pid: int) -> float:
    """utime + stime of a process from /proc/<pid>/stat, s (NaN once it is gone)."""
    try:
        fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    except OSError:
        return float('nan')
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def pair_latencies(sensor: np.ndarray, estimate: np.ndarray, command: np.ndarray,
                   use_stamps: bool, window_s: float = PAIR_WINDOW_S) -> tuple[np.ndarray, int]:
    """Latency from each sensor message to the command it leads to; and how many had none.

    Each array is (n, 2): receive time, header stamp (s), in receive order. A sensor
    message with stamp S leads to the first command received after the first
    estimate (odometry) received among those stamped >= S. Its time is S when
    ``use_stamps`` (wall-clock stamps), else its own receive time.
    """
    latencies: list[float] = []
    lost = 0
    if len(estimate) == 0 or len(command) == 0:
        return np.array([]), len(sensor)
    by_stamp = estimate[np.argsort(estimate[:, 1], kind='stable')]
    first_received = np.minimum.accumulate(by_stamp[::-1, 0])[::-1]
    for recv_s, stamp_s in sensor:
        k = np.searchsorted(by_stamp[:, 1], stamp_s, side='left')
        if k >= len(by_stamp):
            continue  # the window ended before an estimate could contain it
        j = np.searchsorted(command[:, 0], first_received[k], side='right')
        sensor_time = stamp_s if use_stamps else recv_s
        if j >= len(command) or command[j, 0] - sensor_time > window_s:
            lost += 1
            continue
        latencies.append(command[j, 0] - sensor_time)
    return np.array(latencies), lost
