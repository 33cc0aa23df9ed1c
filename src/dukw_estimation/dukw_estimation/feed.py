"""Hand any sensor reading to the estimator: a dispatch by reading type. ROS-free.

Offline drivers of the estimator (evaluate, the in-process stack harness) use this;
ekf_node routes by topic instead (tracks/status and props/status carry one type).
"""
from __future__ import annotations

from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  WaterContact)

_ADD = {ImuSample: 'add_imu', GpsFix: 'add_gps_fix', GpsVelocity: 'add_gps_velocity',
        WaterContact: 'add_water_contact', DepthReading: 'add_depth'}
_DRIVE_ADD = {'tracks': 'add_tracks', 'props': 'add_props'}


def feed(estimator, reading):
    """Call the estimator's ``add_*`` for ``reading``; return its outcome.

    TypeError for a type that is no sensor reading, ValueError for a DriveStatus
    that does not say its drive; the estimator is then left unchanged.
    """
    if isinstance(reading, DriveStatus):
        name = _DRIVE_ADD.get(reading.drive)
        if name is None:
            raise ValueError(f'DriveStatus.drive must be one of {tuple(_DRIVE_ADD)}, '
                             f'got {reading.drive!r}')
    else:
        name = _ADD.get(type(reading))
        if name is None:
            raise TypeError(f'not a sensor reading: {type(reading).__name__}')
    return getattr(estimator, name)(reading)
