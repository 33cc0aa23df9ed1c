"""evaluate: the estimator's accuracy on simulator runs, offline (no DDS).

Each scenario runs the simulator core (dukw_sim.core.SimCore) with its seeded sensor
model (dukw_sim.sensors.SensorModel), feeds the readings - never the truth - through the
estimator core, and scores the estimates against the truth. One JSON object per scenario:

    install/lib/dukw_estimation/evaluate [--scenario NAME ...] [--duration S] [--seed N]
                                         [--oracle-surface]

``--oracle-surface`` is a diagnostic: the estimator is handed the true waterline distance
and wave elevation at base_link before every output, so what is left of the submersion
error is the model's and the float/ground logic's, not the state estimate's.

Targets (issue 5): position RMSE <= 0.5 m, heading <= 3 deg, slip <= 0.05, submerged
volume <= 10 % of the full displacement volume, weight-on-tracks fraction <= 0.1.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from dukw_common.config import ConfigError, node_params
from dukw_common.geometry import euler_from_quaternion
from dukw_common.vehicle import Vehicle, soil_params
from dukw_estimation import samples as est_samples
from dukw_estimation.estimator import Estimator
from dukw_estimation.settings import EkfSettings

TARGETS = {'position_rmse_m': 0.5, 'heading_rmse_deg': 3.0, 'slip_rmse': 0.05,
           'volume_error_pct': 10.0, 'fraction_error': 0.1}
WARM_UP_S = 2.0                # scored from here: the filter has had a fix and a heading
MOVING_TRACK_MPS = 0.1         # slip is scored only where the track turns


@dataclass(frozen=True)
class Scenario:
    """One simulator run: where it starts, the sea, and the commands."""

    name: str
    start: str                                  # 'flat' | 'sand' | 'afloat' | 'sea'
    yaw_rad: float
    tracks_pct: tuple[float, float] = (0.0, 0.0)
    props_pct: tuple[float, float] = (0.0, 0.0)
    wave_height_m: float = 0.0


def scenarios() -> list[Scenario]:
    """The issue's set: land circle, transitions at 64/100 % in 8/28 cm seas, water circle."""
    out = [Scenario('land_circle', 'flat', 0.0, tracks_pct=(56.0, 100.0))]
    for height in (0.08, 0.28):
        for command in (64.0, 100.0):
            tag = f'{int(command)}pct_{int(round(height * 100))}cm'
            out.append(Scenario(f'land_to_sea_{tag}', 'sand', 0.0, (command, command),
                                wave_height_m=height))
            out.append(Scenario(f'sea_to_land_{tag}', 'sea', math.pi, (command, command),
                                wave_height_m=height))
    out.append(Scenario('water_circle', 'afloat', 0.0, props_pct=(100.0, 40.0)))
    return out


def _wave_overrides(height_m: float) -> dict:
    if height_m <= 0.0:
        return {'waves.model': 'none'}
    return {'waves.model': 'irregular', 'waves.significant_height_m': height_m}


class SensorAdapter:
    """The simulator's sensor readings -> the estimator's sample dataclasses."""

    def __init__(self, estimator: Estimator) -> None:
        self.est = estimator

    def feed(self, reading) -> None:
        """Hand one reading to the estimator (by its simulator type name)."""
        kind = type(reading).__name__
        handler: Callable | None = getattr(self, f'_{kind}', None)
        if handler is None:
            raise TypeError(f'no adapter for simulator reading {kind}')
        handler(reading)

    def _ImuReading(self, r) -> None:  # noqa: N802 (named after the reading type)
        roll, pitch, yaw = euler_from_quaternion(*r.orientation_xyzw)
        w, a = r.angular_velocity_rps, r.linear_acceleration_mps2
        self.est.add_imu(est_samples.ImuSample(r.t_s, roll, pitch, yaw, w[0], w[1], w[2],
                                               a[0], a[1], a[2], r.orientation_var[2],
                                               r.angular_velocity_var[2]))

    def _GpsFix(self, r) -> None:  # noqa: N802
        self.est.add_gps_fix(est_samples.GpsFix(r.t_s, r.latitude_deg, r.longitude_deg,
                                                r.altitude_m, r.position_var[0]))

    def _GpsVelocity(self, r) -> None:  # noqa: N802
        v = r.velocity_enu_mps
        self.est.add_gps_velocity(est_samples.GpsVelocity(r.t_s, v[0], v[1], r.velocity_var[0]))

    def _WaterContactReading(self, r) -> None:  # noqa: N802
        self.est.add_water_contact(est_samples.WaterContact(r.t_s, r.fore_wet, r.aft_wet))

    def _DepthReading(self, r) -> None:  # noqa: N802
        self.est.add_depth(est_samples.DepthReading(r.t_s, r.valid, r.depth_m))

    def _DrivetrainReading(self, r) -> None:  # noqa: N802
        def side(m) -> est_samples.MotorSide:
            return est_samples.MotorSide(m.command_pct, m.current_a, m.speed_mps, m.force_n)
        status = est_samples.DriveStatus(r.t_s, side(r.port), side(r.stbd), r.connected)
        (self.est.add_tracks if r.drive == 'tracks' else self.est.add_props)(status)


def build_estimator(vehicle: Vehicle, datum: tuple[float, float, float],
                    config: str | None = None) -> Estimator:
    """The estimator as ekf_node configures it, its datum the simulator's survey origin."""
    params = node_params('ekf_node', config)
    settings = dataclasses.replace(EkfSettings.from_params(params), datum_from_first_fix=False,
                                   datum_latitude_deg=datum[0], datum_longitude_deg=datum[1],
                                   datum_altitude_m=datum[2])
    return Estimator(vehicle, settings, soil_params(params, settings.soil_preset or None))


def run_scenario(scenario: Scenario, duration_s: float = 30.0, seed: int = 0,
                 config: str | None = None, oracle_surface: bool = False) -> dict:
    """Run one scenario; return its metrics (and whether each target is met).

    ``oracle_surface``: pin the estimator's waterline distance and wave to the truth's after
    every reading (a diagnostic of where the submersion error comes from).
    """
    from dukw_sim.core import Actuation, SimCore
    from dukw_sim.sensors import SensorModel
    sim = SimCore.from_config(config, overrides=_wave_overrides(scenario.wave_height_m),
                              seed=seed)
    sensors = SensorModel.from_config(config, seed=seed)
    vehicle = sim.vehicle
    sim.reset(scenario.start, yaw_rad=scenario.yaw_rad)     # SimCore.start_x_m
    gps = sensors.config.datum
    est = build_estimator(vehicle, (gps.latitude_deg, gps.longitude_deg, gps.altitude_m),
                          config)
    adapter = SensorAdapter(est)
    act = Actuation(*scenario.tracks_pct, *scenario.props_pct)
    rows = []
    truth = sim.truth
    for _ in range(int(round(duration_s / sim.dt_s))):
        truth = sim.step(act)
        for reading in sensors.sample(truth):
            adapter.feed(reading)
            if oracle_surface:
                est.pin_surface(truth.waterline_distance_m, truth.wave_elevation_m)
        if truth.t_s < WARM_UP_S or est.t_s is None:
            continue
        odo, trc = est.odometry(), est.traction()
        rows.append((odo.x_m - truth.x_m, odo.y_m - truth.y_m,
                     math.remainder(odo.yaw_rad - truth.yaw_rad, 2 * math.pi),
                     trc.port_slip - truth.port_slip, trc.stbd_slip - truth.stbd_slip,
                     abs(truth.port_track_speed_mps) > MOVING_TRACK_MPS,
                     abs(truth.stbd_track_speed_mps) > MOVING_TRACK_MPS,
                     trc.submerged_volume_m3 - truth.submerged_volume_m3,
                     trc.weight_on_tracks_fraction - truth.weight_on_tracks_fraction))
    result = score(scenario, np.array(rows, dtype=float), vehicle, truth, est)
    if oracle_surface:
        result['oracle'] = 'surface'
    return result


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values)))) if values.size else 0.0


def score(scenario: Scenario, rows: np.ndarray, vehicle: Vehicle, last_truth, est) -> dict:
    """Metrics of one run from the per-step errors."""
    slip_err = np.concatenate([rows[rows[:, 5] > 0, 3], rows[rows[:, 6] > 0, 4]])
    out = {
        'scenario': scenario.name,
        'position_rmse_m': _rms(np.hypot(rows[:, 0], rows[:, 1])),
        'heading_rmse_deg': math.degrees(_rms(rows[:, 2])),
        'slip_rmse': _rms(slip_err),
        'volume_error_pct': 100.0 * _rms(rows[:, 7]) / vehicle.body.displaced_volume_m3,
        'fraction_error': _rms(rows[:, 8]),
        'scored_s': round(rows.shape[0] * 0.01, 2),
        'end_medium': last_truth.medium.name,
        'rejected': {s: sum(n for o, n in c.items() if o.value.startswith('rejected'))
                     for s, c in est.counters.items()},
    }
    out = {k: (round(v, 4) if isinstance(v, float) else v) for k, v in out.items()}
    out['targets_met'] = all(out[k] <= limit for k, limit in TARGETS.items())
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point: one JSON line per scenario; exit 1 if a target is missed."""
    names = [s.name for s in scenarios()]
    parser = argparse.ArgumentParser(prog='evaluate', description=__doc__.split('\n\n')[0])
    parser.add_argument('--scenario', action='append', choices=names,
                        help='run only this scenario (repeatable); default: all')
    parser.add_argument('--duration', type=float, default=30.0, help='seconds per run')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--config', help="parameter file (default: the stack's)")
    parser.add_argument('--oracle-surface', action='store_true',
                        help='diagnostic: hand the estimator the true waterline distance and '
                             'wave at base_link, to see the error not due to the state estimate')
    args = parser.parse_args(argv)
    if not args.duration > WARM_UP_S:
        parser.error(f'--duration must be longer than the {WARM_UP_S} s warm-up')
    chosen = [s for s in scenarios() if not args.scenario or s.name in args.scenario]
    ok = True
    try:
        for scenario in chosen:
            result = run_scenario(scenario, args.duration, args.seed, args.config,
                                  args.oracle_surface)
            ok &= result['targets_met']
            print(json.dumps(result), flush=True)
    except ConfigError as exc:
        print(f'evaluate: {exc}', file=sys.stderr)
        return 2
    return 0 if ok else 1


if __name__ == '__main__':
    raise SystemExit(main())
