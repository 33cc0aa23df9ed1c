"""The motor-controller monitor: Roboteq replies -> per-side status (ROS-free).

The node is a MONITOR: it only queries. Motor commands reach the controllers as
RC pulses from the servo switch through the RC multiplexer, so the RC operator
always wins in hardware. Sending ``!G`` over serial would put the controller in
serial command mode, which (when serial has the higher command priority) holds
off the pulse input until the serial watchdog expires, and forever if the
watchdog is disabled. So the monitor reads ``~RWD`` and reports a disabled
watchdog, and reports the controller being in serial mode, on /diagnostics.

Per side: command from ``?M`` (percent), current ``?A``, battery voltage ``?V``,
temperature ``?T`` (the channel's heat sink), faults ``?FF`` + ``?FM``. Tracks:
speed from the motor RPM through the reduction and the drive sprocket, force =
current x gain (8.16 N/A, vehicle.md section 3). Propellers: no encoder, speed
0; force is a thrust estimate from the applied command, linear up to the rated
133 N forward and the reverse share backwards (``dukw_model.propeller``, the
simulator's model too).
"""
from __future__ import annotations

import math
from enum import Enum

from dukw_common.config import ConfigError
from dukw_common.readings import MotorSide
from dukw_common.vehicle import DrivetrainParams
from dukw_model.propeller import prop_thrust_n
from dukw_driver.roboteq import (CONFIG_QUERIES, FAULT_COMM_TIMEOUT, QUERIES, ReplyParser,
                                 config_frame, decode_faults, decode_status, query_frame)


class Drive(Enum):
    """Which pair of motors a controller drives (dukw_msgs/DrivetrainStatus DRIVE_*)."""

    TRACKS = 0
    PROPS = 1

    @classmethod
    def parse(cls, text: str) -> 'Drive':
        """'tracks' or 'props' -> Drive; ConfigError naming the parameter otherwise."""
        try:
            return {'tracks': cls.TRACKS, 'props': cls.PROPS}[text]
        except KeyError:
            raise ConfigError(f"parameter 'drive' must be 'tracks' or 'props', got {text!r}") \
                from None


def track_speed_mps(motor_rpm: float, drivetrain: DrivetrainParams) -> float:
    """Track belt speed from the motor's RPM: through the reduction to the drive sprocket."""
    sprocket_rps = motor_rpm / drivetrain.gear_reduction / 60.0
    return sprocket_rps * math.pi * drivetrain.sprocket_diameter_m


#: A channel the controller does not answer for (one motor channel: readings.MotorSide).
UNKNOWN_SIDE = MotorSide(math.nan, math.nan, math.nan, math.nan, voltage_v=math.nan,
                         temperature_c=math.nan, fault_flags=FAULT_COMM_TIMEOUT,
                         faults=('comm_timeout',))


class MotorMonitor:
    """Keeps the latest replies of one controller and turns them into port/stbd status.

    ``port_channel`` is the controller channel (1 or 2) driving the port motor.
    Status is ``connected`` only while every runtime query was answered within
    ``stale_after_s``; otherwise both sides read NaN with FAULT_COMM_TIMEOUT.
    """

    def __init__(self, drive: Drive, drivetrain: DrivetrainParams, port_channel: int = 1,
                 stale_after_s: float = 0.5) -> None:
        if port_channel not in (1, 2):
            raise ConfigError(f"parameter 'port_channel' must be 1 or 2, got {port_channel!r}")
        self.drive = drive
        self.drivetrain = drivetrain
        self.port_index = port_channel - 1
        self.stale_after_s = stale_after_s
        self.parser = ReplyParser()
        self.values: dict[str, tuple[int, ...]] = {}
        self.stamps: dict[str, float] = {}
        self.watchdog_ms: int | None = None

    def feed(self, data: bytes, now_s: float) -> bool:
        """Take received bytes; True if a full, fresh set of replies is now available."""
        for name, values in self.parser.feed(data).items():
            if name in CONFIG_QUERIES:
                self.watchdog_ms = values[0]
                continue
            self.values[name] = values
            self.stamps[name] = now_s
        return self.fresh(now_s)

    def fresh(self, now_s: float) -> bool:
        """True while every runtime query has an answer younger than ``stale_after_s``."""
        return all(now_s - self.stamps.get(n, -math.inf) <= self.stale_after_s for n in QUERIES)

    def forget(self) -> None:
        """The link went down: drop every value (and the watchdog reading)."""
        self.values.clear()
        self.stamps.clear()
        self.watchdog_ms = None

    def queries(self) -> bytes:
        """Bytes to send this cycle: the runtime queries, and the watchdog until it is known."""
        return query_frame() + (config_frame() if self.watchdog_ms is None else b'')

    def sides(self, now_s: float) -> tuple[MotorSide, MotorSide]:
        """(port, stbd) status now."""
        if not self.fresh(now_s):
            return UNKNOWN_SIDE, UNKNOWN_SIDE
        v = self.values
        out = []
        for index in (self.port_index, 1 - self.port_index):
            command_pct = v['M'][index] / 10.0
            current_a = v['A'][index] / 10.0
            if self.drive == Drive.TRACKS:
                speed = track_speed_mps(v['S'][index], self.drivetrain)
                force = current_a * self.drivetrain.track_force_gain_n_per_a
            else:
                speed, force = 0.0, prop_thrust_n(command_pct, self.drivetrain)
            report = decode_faults(v['FF'][0], v['FM'][index])
            out.append(MotorSide(command_pct, current_a, speed, force,
                                 voltage_v=v['V'][1] / 10.0,
                                 temperature_c=float(v['T'][1 + index]),
                                 fault_flags=report.flags, faults=report.names))
        return out[0], out[1]

    def warnings(self) -> list[str]:
        """Things the operator should know that are not motor faults."""
        found = []
        if self.watchdog_ms == 0:
            found.append('serial watchdog disabled (~RWD 0): a stray serial command would '
                         'hold off the RC pulse input')
        status = decode_status(self.values['FS'][0]) if 'FS' in self.values else []
        if 'serial_mode' in status:
            found.append('controller in serial command mode: something sends !G commands')
        if 'power_stage_off' in status:
            found.append('power stage off')
        return found
