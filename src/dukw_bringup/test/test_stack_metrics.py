"""Latency pairing and CPU time of the stack benchmark."""
import math
import os

import numpy as np
import pytest

from dukw_bringup.stack_metrics import cpu_seconds, pair_latencies


def test_each_sensor_message_pairs_with_the_command_after_its_estimate():
    # imu at 0.000 / 0.010 s (stamps = wall), odometry stamped like the imu 2 ms later,
    # commands on a timer at 0.005, 0.015, 0.025
    sensor = np.array([[0.0005, 0.000], [0.0105, 0.010]])
    estimate = np.array([[0.002, 0.000], [0.012, 0.010]])
    command = np.array([[0.005, 0.0], [0.015, 0.0], [0.025, 0.0]])
    latencies, lost = pair_latencies(sensor, estimate, command, use_stamps=True)
    assert latencies == pytest.approx([0.005, 0.005]) and lost == 0
    latencies, _ = pair_latencies(sensor, estimate, command, use_stamps=False)
    assert latencies == pytest.approx([0.0045, 0.0045])


def test_a_command_before_the_estimate_does_not_count():
    sensor = np.array([[0.0, 0.0]])
    estimate = np.array([[0.006, 0.0]])
    command = np.array([[0.004, 0.0], [0.009, 0.0]])
    latencies, _ = pair_latencies(sensor, estimate, command, use_stamps=True)
    assert latencies == pytest.approx([0.009])


def test_no_command_in_the_window_is_lost():
    sensor = np.array([[0.0, 0.0]])
    estimate = np.array([[0.001, 0.0]])
    latencies, lost = pair_latencies(sensor, estimate, np.array([[0.5, 0.0]]), use_stamps=True)
    assert len(latencies) == 0 and lost == 1
    assert pair_latencies(sensor, estimate, np.empty((0, 2)), use_stamps=True)[1] == 1


def test_cpu_seconds_of_this_process_and_of_a_missing_one():
    assert cpu_seconds(os.getpid()) > 0.0
    assert math.isnan(cpu_seconds(2 ** 22 + 12345))
