"""Latency pairing (from the processes' traces) and CPU time of the stack benchmark."""
import ctypes
import math
import os
import threading
import time

import pytest

from dukw_bringup.stack_metrics import chain_latencies, cpu_seconds, thread_cpu_seconds


MS = 1_000_000
IMU, ODOM, CMD = '/imu/data', '/odometry/filtered', '/tracks/cmd'


def sim_trace(stamps_ms):
    """The simulator publishes imu/data stamped S at wall S (ms, here as ns)."""
    return [('pub', IMU, s * MS, s * MS, s * MS + MS // 10, None) for s in stamps_ms]


def test_a_command_traces_back_through_every_hop_to_its_sample():
    # separate processes: imu 0 -> ekf takes at 0.3, odometry (stamp 0) at 0.5 -> controller
    # takes at 0.8, command (clock stamp 7) at 0.9 -> actuator at 1.2 ms
    traces = {'sim': sim_trace([0]),
              'ekf': [('take', IMU, 0, 3 * MS // 10, MS, None),
                      ('pub', ODOM, 0, MS // 2, 6 * MS // 10, (IMU, 0))],
              'ctrl': [('take', ODOM, 0, 8 * MS // 10, MS, None),
                       ('pub', CMD, 7, 9 * MS // 10, MS, (ODOM, 0))]}
    result = chain_latencies(traces, [(12 * MS // 10, 7)], (0, 10 * MS))
    assert result.total_s == pytest.approx([0.0012])
    assert result.sensor_delivery_s == pytest.approx([0.0003])
    assert result.in_chain_s == pytest.approx([0.0006])
    assert result.command_delivery_s == pytest.approx([0.0003]) and result.lost == 0


def test_a_timer_command_or_one_never_taken_does_not_count():
    # composed: the command of imu 0 goes out in its callback; a timer command (no cause) at
    # 2 ms; imu 10's command is never taken: lost. An actuator take of another stamp is
    # skipped (a command the trace does not know, e.g. before the actuator matched).
    traces = {'sim': sim_trace([0, 10]),
              'chain': [('take', IMU, 0, MS // 5, MS, None),
                        ('pub', CMD, 5, MS // 2, MS // 2, (IMU, 0)),
                        ('pub', CMD, 6, 2 * MS, 2 * MS, None),
                        ('take', IMU, 10 * MS, 10 * MS, 11 * MS, None),
                        ('pub', CMD, 8, 11 * MS, 11 * MS, (IMU, 10 * MS))]}
    takes = [(MS // 4, 99), (MS, 5), (3 * MS, 6)]
    result = chain_latencies(traces, takes, (0, 20 * MS))
    assert result.total_s == pytest.approx([0.001]) and result.lost == 1


def test_a_sample_outside_the_window_or_its_command_too_late_is_not_counted():
    traces = {'sim': sim_trace([0, 10]),
              'chain': [('take', IMU, 0, 0, MS, None), ('pub', CMD, 1, MS, MS, (IMU, 0)),
                        ('take', IMU, 10 * MS, 10 * MS, 11 * MS, None),
                        ('pub', CMD, 2, 11 * MS, 11 * MS, (IMU, 10 * MS))]}
    takes = [(2 * MS, 1), (500 * MS, 2)]
    result = chain_latencies(traces, takes, (5 * MS, 20 * MS))
    assert len(result.total_s) == 0 and result.lost == 1
    assert len(chain_latencies(traces, takes, (0, 5 * MS)).total_s) == 1


def test_cpu_seconds_of_this_process_and_of_a_missing_one():
    assert cpu_seconds(os.getpid()) > 0.0
    assert math.isnan(cpu_seconds(2 ** 22 + 12345))


def test_thread_cpu_seconds_counts_only_the_named_threads():
    """A busy thread named dds.* (as Fast DDS names its threads) is counted, the busy main
    thread of this process is not; a missing process gives NaN."""
    libc = ctypes.CDLL(None, use_errno=True)
    before = thread_cpu_seconds(os.getpid())

    def busy() -> None:
        libc.prctl(15, b'dds.test_busy', 0, 0, 0)        # PR_SET_NAME: this thread's name
        end = time.thread_time() + 0.3       # its own CPU: the process's other threads
        while time.thread_time() < end:      # (an xdist worker's) must not end it early
            pass
    thread = threading.Thread(target=busy)
    thread.start()
    counted = before
    while thread.is_alive():     # the most seen: a thread past its loop may be gone from /proc
        counted = max(counted, thread_cpu_seconds(os.getpid()))
        time.sleep(0.05)
    thread.join()
    assert counted - before >= 0.1
    main_before = thread_cpu_seconds(os.getpid())
    end = time.process_time() + 0.2
    while time.process_time() < end:      # the main thread (not dds.*) busy
        pass
    assert thread_cpu_seconds(os.getpid()) - main_before < 0.05
    assert thread_cpu_seconds(os.getpid(), prefix='no-such-thread') == 0.0
    assert math.isnan(thread_cpu_seconds(2 ** 22 + 12345))
