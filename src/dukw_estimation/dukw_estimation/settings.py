"""The estimator's tuning, robot_localization style, as one typed dataclass.

Every field is an ``ekf_node`` parameter in config/dukw.yaml (dotted names, e.g.
``noise.gps_position_m``); ``SETTING_SPECS`` gives each one's meaning and range so the
node declares them without repeating the list. Geometry and soil come from ``Vehicle``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Mapping

from dukw_common.config import ConfigError, ParamValue

_KINDS = {'float': float, 'bool': bool, 'str': str}
SENSORS = ('imu', 'gps_fix', 'gps_vel', 'water', 'depth', 'tracks', 'props')


def _f(name: str, description: str, lo: float | None = None, hi: float | None = None):
    return field(metadata={'name': name, 'description': description, 'min': lo, 'max': hi})


@dataclass(frozen=True)
class EkfSettings:
    """Filter tuning. Sigmas are one standard deviation; process noise per sqrt(second)."""

    rate_hz: float = _f('rate_hz', 'output rate of odometry/filtered and traction, Hz', 0.1, 1000)
    sensor_timeout_s: float = _f('sensor_timeout_s',
                                 'a sensor silent this long is stale (predict-only, WARN)',
                                 0.01, 60)
    max_lag_s: float = _f('max_lag_s', 'measurements older than the filter by more than this '
                          'are rejected as out of order; younger ones apply at filter time',
                          0.0, 10)
    # datum of the local ENU frame
    datum_from_first_fix: bool = _f('datum.from_first_fix',
                                    'take the datum from the first GPS fix')
    datum_latitude_deg: float = _f('datum.latitude_deg', 'datum latitude', -90, 90)
    datum_longitude_deg: float = _f('datum.longitude_deg', 'datum longitude', -180, 180)
    datum_altitude_m: float = _f('datum.altitude_m', 'datum altitude', -1e4, 1e4)
    # the shore in odom
    waterline_x_m: float = _f('shore.waterline_x_m', 'a point on the mean waterline, odom x',
                              -1e6, 1e6)
    waterline_y_m: float = _f('shore.waterline_y_m', 'a point on the mean waterline, odom y',
                              -1e6, 1e6)
    seaward_yaw_rad: float = _f('shore.seaward_yaw_rad',
                                'direction pointing seaward, perpendicular to the waterline',
                                -math.pi, math.pi)
    waterline_sigma_m: float = _f('shore.waterline_sigma_m',
                                  'uncertainty of the surveyed waterline (tide, survey)', 0, 100)
    # per-sensor enable
    use_imu: bool = _f('enable.imu', 'fuse imu/data')
    use_gps_fix: bool = _f('enable.gps_fix', 'fuse gps/fix')
    use_gps_vel: bool = _f('enable.gps_vel', 'fuse gps/vel')
    use_water: bool = _f('enable.water', 'fuse water/contact')
    use_depth: bool = _f('enable.depth', 'fuse depth')
    use_tracks: bool = _f('enable.tracks', 'use tracks/status (slip, forces, drive model)')
    use_props: bool = _f('enable.props', 'use props/status (drive model afloat)')
    # measurement noise (used when a message carries no covariance)
    gps_position_m: float = _f('noise.gps_position_m', 'DGPS position sigma', 1e-4, 100)
    gps_velocity_mps: float = _f('noise.gps_velocity_mps', 'DGPS velocity sigma', 1e-4, 10)
    track_speed_sigma_mps: float = _f(
        'noise.track_speed_mps', "a belt's speed reading sigma (the encoder's noise; 0: the "
        'readings exact)', 0, 1)
    yaw_rad: float = _f('noise.yaw_rad', 'IMU/compass heading sigma', 1e-5, 1)
    gyro_rps: float = _f('noise.gyro_rps', 'gyro z sigma', 1e-6, 1)
    contact_m: float = _f('noise.contact_m', 'water surface at a wet/dry boundary sigma',
                          1e-4, 1)
    contact_surface_slope: float = _f(
        'noise.contact_surface_slope', "the sea surface's slope over the hulls, sigma (rad): "
        "a wet/dry sensor's surface, taken as level to base_link, is off by it times the "
        "sensor's distance from base_link", 0, 1)
    depth_m: float = _f('noise.depth_m', 'depth sounder sigma (incl. heave)', 1e-4, 5)
    track_odometry_mps: float = _f('noise.track_odometry_mps',
                                   'track-speed pseudo-measurement sigma (GPS stale)', 1e-3, 10)
    track_odometry_period_s: float = _f(
        'noise.track_odometry_period_s', 'at most this often (the held slips are one error '
        'for the dropout, not a new one at each status), s', 0, 60)
    # process noise
    q_position_m: float = _f('process.position_m', 'position random walk', 0, 10)
    q_yaw_rad: float = _f('process.yaw_rad', 'heading random walk', 0, 10)
    q_accel_mps2: float = _f('process.accel_mps2',
                             'velocity noise with IMU accelerations as input', 1e-6, 100)
    q_accel_no_imu_mps2: float = _f('process.accel_no_imu_mps2',
                                    'velocity noise without the IMU (drive model)', 1e-6, 100)
    q_yaw_accel_rps2: float = _f('process.yaw_accel_rps2', 'yaw-rate random walk', 1e-6, 100)
    q_gyro_bias_rps: float = _f('process.gyro_bias_rps', 'gyro bias random walk', 0, 1)
    q_waterline_m: float = _f('process.waterline_m', 'waterline distance random walk', 0, 10)
    q_accel_bias_mps2: float = _f(
        'process.accel_bias_mps2', "sigma of the surge and sway accelerations' slow error "
        "(gravity through the IMU's attitude error; Gauss-Markov states, 0: none)", 0, 10)
    q_accel_bias_tau_s: float = _f('process.accel_bias_tau_s', 'its correlation time',
                                   0.1, 1e4)
    # initial covariance (sigmas)
    init_position_m: float = _f('initial_sigma.position_m', 'initial position sigma', 1e-4, 1e4)
    init_yaw_rad: float = _f('initial_sigma.yaw_rad', 'initial heading sigma', 1e-4, 10)
    init_velocity_mps: float = _f('initial_sigma.velocity_mps', 'initial velocity sigma',
                                  1e-4, 100)
    init_yaw_rate_rps: float = _f('initial_sigma.yaw_rate_rps', 'initial yaw-rate sigma',
                                  1e-4, 10)
    init_gyro_bias_rps: float = _f('initial_sigma.gyro_bias_rps', 'initial gyro-bias sigma',
                                   1e-6, 1)
    # Mahalanobis rejection thresholds (distance, not squared)
    gate_imu: float = _f('mahalanobis.imu', 'IMU heading/gyro rejection distance', 0.5, 1e6)
    gate_gps_fix: float = _f('mahalanobis.gps_fix', 'GPS position rejection distance', 0.5, 1e6)
    gate_gps_vel: float = _f('mahalanobis.gps_vel', 'GPS velocity rejection distance', 0.5, 1e6)
    gate_water: float = _f('mahalanobis.water', 'water-contact rejection distance', 0.5, 1e6)
    gate_depth: float = _f('mahalanobis.depth', 'depth rejection distance', 0.5, 1e6)
    # wave surface at the vehicle: a damped oscillator driven by noise
    wave_peak_frequency_hz: float = _f('wave.peak_frequency_hz',
                                       'dominant wave frequency (vehicle.md 5: 0.27-0.29)',
                                       0.01, 5)
    wave_damping_ratio: float = _f('wave.damping_ratio', 'oscillator damping (sea bandwidth)',
                                   0.01, 2)
    wave_sigma_m: float = _f('wave.sigma_m', 'wave elevation sigma, ~ H1/3 / 4', 0, 2)
    heave_natural_hz: float = _f('seakeeping.heave_natural_hz',
                                 'heave natural frequency afloat (vehicle.md 5: 0.5731)', 0.01, 10)
    heave_damping_ratio: float = _f('seakeeping.heave_damping_ratio',
                                    'heave damping ratio afloat (the damping force joins the '
                                    'heave acceleration in the afloat volume)', 0, 2)
    q_heave_accel_mps2: float = _f('heave.accel_noise_mps2', "heave rate's noise with the "
                                   "IMU's vertical acceleration as input (per sqrt(s))",
                                   1e-6, 100)
    heave_surface_m: float = _f('heave.surface_sigma_m', 'afloat: the keel under the wave by '
                                'the dynamic draft, sigma', 1e-4, 1)
    heave_ground_m: float = _f('heave.ground_sigma_m', 'on the sand: the keel on the beach, '
                               'sigma', 1e-4, 1)
    heave_gate: float = _f('heave.mahalanobis', 'rejection distance of both', 0.5, 1e6)
    heave_keel_at_beach_m: float = _f('heave.keel_at_beach_m', 'afloat, the keel this close '
                                      'to the estimated beach may lie on it: the dynamic draft '
                                      'then bounds the water from above only (0: off)', 0, 1)
    init_heave_m: float = _f('initial_sigma.heave_m', "initial sigma of the keel's height",
                             1e-4, 100)
    init_heave_rate_mps: float = _f('initial_sigma.heave_rate_mps',
                                    'initial heave-rate sigma', 1e-4, 100)
    contact_rate_rps: float = _f('contact.rate_threshold_rps', 'roll/pitch rate scale above '
                                 'which the hull is taken to float (grounded: ~0)', 1e-4, 10)
    contact_accel_mps2: float = _f('contact.accel_threshold_mps2',
                                   'heave acceleration scale for the same test', 1e-4, 100)
    contact_time_constant_s: float = _f('contact.time_constant_s',
                                        'low-pass of that motion test', 1e-3, 10)
    contact_impact_heave_rate_mps: float = _f(
        'contact.impact_heave_rate_mps', 'the fastest a floating hull heaves: a heave '
        'acceleration beyond what the buoyancy of the hulls awash and the damping at this '
        'rate give is the sand striking the keel (0: off)', 0, 10)
    contact_min_volume_share: float = _f('contact.min_volume_share',
                                         'floating needs at least this share of the '
                                         'displacement under water (bumps on land)', 0, 1)
    contact_track_force_n: float = _f('contact.track_force_n', 'both tracks pushing or '
                                      'braking this hard past their friction touch the sand, '
                                      'whatever the IMU says (water gives less; 0: off)',
                                      0, 1e4)
    gps_bias_sigma_m: float = _f('gps_bias.sigma_m', 'slowly drifting DGPS position error '
                                 'sigma (0: no bias states, message covariance used)', 0, 100)
    gps_bias_tau_s: float = _f('gps_bias.tau_s', 'correlation time of the DGPS error', 0.01,
                               1e5)
    # beach slope from pitch/roll
    slope_time_constant_s: float = _f('slope.time_constant_s', 'low-pass of the pitch slope',
                                      0.01, 100)
    slope_min_fraction: float = _f('slope.min_fraction', 'the slope is learnt while the '
                                   'contact decision says on the sand and the tracks carry at '
                                   'least this share of the weight (the hull lies on the '
                                   "beach: its pitch is the beach's)", 0, 1)
    # drive model (no IMU, or GPS stale)
    drive_time_constant_s: float = _f('drive_model.time_constant_s',
                                      'velocity lag behind the tracks / thrust', 0.01, 100)
    effective_track_width_m: float = _f('drive_model.effective_track_width_m',
                                        'skid-steer effective track separation', 0.1, 10)
    water_drag_n_per_mps2: float = _f('drive_model.water_drag_n_per_mps2',
                                      'quadratic surge drag afloat (266 N at 1.2 m/s)', 1, 1e5)
    # track forces
    force_process_n_per_s: float = _f('force_filter.process_n_per_s',
                                      'track-force smoother: force rate noise', 1e-3, 1e5)
    force_measurement_n: float = _f('force_filter.measurement_n',
                                    'track-force smoother: current x gain noise', 1e-3, 1e4)
    slip_stopped_track_mps: float = _f(
        'slip.stopped_track_mps', 'a track reported slower than this counts as stopped for '
        'its slip (its sign is the encoder noise: a spinning-up belt read as reversing gave '
        'slip +1 against the truth -1)', 0, 1)
    # zero-velocity update (ZUPT): belts stopped, the IMU still, on the sand -> ground speed 0
    zupt_enabled: bool = _f('zupt.enabled', 'at rest (both belts stopped, the IMU still, not '
                            'afloat) the ground velocity is measured as zero')
    zupt_window_s: float = _f('zupt.window_s', "the stance detector's window (stance.py)",
                              0.02, 10)
    zupt_threshold: float = _f('zupt.threshold', "still while the IMU's moving variance, over "
                               'its noise (1 ~ noise alone), stays below this', 1.01, 1e6)
    zupt_accel_sigma_mps2: float = _f('zupt.accel_sigma_mps2', "the IMU's specific force noise "
                                      'per axis where a sample carries no covariance '
                                      '(the angular rates: noise.gyro_rps)', 1e-5, 10)
    zupt_mean_accel_mps2: float = _f('zupt.mean_accel_mps2', "and while the window's mean "
                                     'surge and sway acceleration (gravity removed with the '
                                     "IMU's attitude, the learnt accelerometer bias too) is "
                                     'under this (a steady push varies nothing)', 1e-4, 10)
    zupt_min_fraction: float = _f('zupt.min_fraction', 'and while the tracks carry at least '
                                  'this share of the weight (less: the waves push the hull '
                                  'over the sand steadily, which a still IMU does not show)',
                                  0, 1)
    zupt_sigma_mps: float = _f('zupt.sigma_mps', 'sigma of the zero surge and sway speed '
                               '(what a still IMU and stopped belts leave unseen)', 1e-4, 1)
    zupt_gate: float = _f('zupt.mahalanobis', 'rejection distance of the zero surge and sway '
                          'speed, jointly (2 degrees of freedom: a vehicle moving steadily, '
                          'which the moving variance cannot see)', 0.5, 1e6)
    # the measured track forces as a measurement of the weight on the tracks
    force_update_min_slip: float = _f('force_update.min_slip', 'both tracks slipping at least '
                                      'this much: the Wong force then tells the weight', 0, 1)
    force_update_min_track_speed_mps: float = _f(
        'force_update.min_track_speed_mps', 'both tracks turning at least this fast (the slip '
        'of a nearly stopped track is the ground speed error over its speed)', 0, 10)
    force_update_held_min_ground_mps: float = _f(
        'force_update.held_min_ground_mps', 'both tracks held (slower than '
        'slip.stopped_track_mps) while the ground under both moves at least this fast: their '
        'slip is -1 and the braking force the full shear strength of the soil, which tells the '
        'weight (0: held tracks never update)', 0, 10)
    force_update_sigma_n: float = _f('force_update.sigma_n', 'per track: current noise, '
                                     'unmodelled friction and paddle thrust (0: off)', 0, 1e4)
    force_update_surface_m: float = _f(
        'force_update.surface_sigma_m', "the water at the hulls the one level surface at "
        "base_link does not place, sigma (m): the force's sensitivity to the surface times it "
        "joins each update's noise", 0, 1)
    force_update_period_s: float = _f('force_update.period_s', 'at most this often (the '
                                      'smoothed force is correlated in time)', 0, 60)
    force_update_settle_s: float = _f('force_update.settle_s', 'grounded at least this long '
                                      '(the smoothed force lags a touchdown)', 0, 60)
    force_update_gate: float = _f('force_update.mahalanobis', 'rejection distance: a force far '
                                  'off the model is more likely the model failing (a track '
                                  'half in the air, paddling) than the surface', 0.5, 1e6)
    force_update_max_soil_spread: float = _f(
        'force_update.max_soil_spread', "no force update while the soil's relative force "
        'spread (soil_online) exceeds this: an unknown soil biases the surface (0: off, '
        'the configured soil trusted)', 0, 10)
    force_update_max_slip_spread: float = _f(
        'force_update.max_slip_spread', "no force update where the slip's uncertainty (the "
        "ground speed's and the belt's reading's) "
        "moves the model's force by more than this share of it (a small slip on a soft "
        'soil: the force then tells the slip, not the water; 0: off)', 0, 10)
    contact_bracket_period_s: float = _f(
        'contact.bracket_period_s', 'one water sensor wet, the other dry: the surface as '
        "anywhere between their heights (the span's middle, sigma width / sqrt(12)), at most "
        'this often (0: off)', 0, 60)
    water_dry_bound: bool = _f(
        'contact.dry_bound', 'both water sensors reading dry bound the surface below them: '
        'the surface states are projected onto that bound (a constraint, which confident '
        'track-force updates cannot outvote as they do a gated measurement)')
    soil_scale_sigma: float = _f(
        'soil_scale.sigma', "prior sigma of the soil's strength against the contact model's "
        'soil (a factor on the Wong force, learnt with the surface from the track forces; '
        '0: the soil trusted)', 0, 2)
    soil_scale_process_per_sqrt_s: float = _f(
        'soil_scale.process_per_sqrt_s', "random walk of the soil's strength factor, per "
        'sqrt(s) (the sand changes along the beach)', 0, 1)
    soil_scale_min_fraction: float = _f(
        'soil_scale.min_fraction', "a track-force update moves the soil's factor only where "
        'the tracks carry at least this share of the weight (less: the force is the product '
        'of a small weight and the factor, far from linear in either)', 0, 1)
    soil_scale_from_held_tracks: bool = _f(
        'soil_scale.from_held_tracks', "held belts slid over the sand by the waves move the "
        "soil's factor too (false: their braking force corrects the surface only)")
    soil_scale_min: float = _f('soil_scale.min', "lower bound of the soil's strength factor",
                               0.01, 1)
    soil_scale_max: float = _f('soil_scale.max', "upper bound of the soil's strength factor",
                               1, 100)
    soil_preset: str = _f('soil_preset', "soil preset name; '' uses soil.*")
    # the site's soil learnt online on dry sand (soil_online.py)
    soil_online_enabled: bool = _f('soil_online.enabled', 'learn phi and k of the site from '
                                   'the track forces on dry sand (prior: the configured soil)')
    soil_online_phi_min_rad: float = _f('soil_online.phi_min_rad', 'lower bound of phi', 0, 1.4)
    soil_online_phi_max_rad: float = _f('soil_online.phi_max_rad', 'upper bound of phi', 0, 1.4)
    soil_online_k_min_m: float = _f('soil_online.k_min_m', 'lower bound of k', 0, 1)
    soil_online_k_max_m: float = _f('soil_online.k_max_m', 'upper bound of k', 0, 1)
    soil_online_phi_sigma_rad: float = _f('soil_online.phi_sigma_rad', 'prior sigma of phi',
                                          1e-4, 1)
    soil_online_k_sigma_m: float = _f('soil_online.k_sigma_m', 'prior sigma of k', 1e-4, 1)
    soil_online_force_sigma_n: float = _f('soil_online.force_sigma_n', 'per track: force '
                                          'noise of one update (current, friction)', 0.1, 1e4)
    soil_online_min_slip: float = _f('soil_online.min_slip', 'learn only where |slip| is at '
                                     'least this (past the grip)', 0, 1)
    soil_online_min_track_speed_mps: float = _f('soil_online.min_track_speed_mps', 'and the '
                                                'track turns at least this fast', 0, 10)
    soil_online_max_turn_mps: float = _f('soil_online.max_turn_mps', 'and the two tracks '
                                         'differ by at most this (straight: no skid-steer '
                                         'shear)', 0, 10)
    soil_online_max_slip_sigma: float = _f('soil_online.max_slip_sigma', 'and the slip is '
                                           'known to this (one sigma, from the filter)', 0, 1)
    soil_online_dry_margin_m: float = _f('soil_online.dry_margin_m', 'dry sand: no hull '
                                         'volume even with the surface this much higher', 0, 5)
    soil_online_period_s: float = _f('soil_online.period_s', 'at most this often', 0, 60)

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue]) -> 'EkfSettings':
        """Build from a node's dotted parameters; ConfigError names a missing or bad one."""
        values = {}
        for f in fields(cls):
            name = f.metadata['name']
            if name not in params:
                raise ConfigError(f'ekf_node: missing parameter {name!r}')
            value = params[name]
            kind = _KINDS[f.type]
            if kind is bool:
                if not isinstance(value, bool):
                    raise ConfigError(f'ekf_node: parameter {name!r} must be a bool')
            elif kind is float:
                if isinstance(value, bool) or not isinstance(value, (int, float)) \
                        or not math.isfinite(value):
                    raise ConfigError(f'ekf_node: parameter {name!r} must be a finite number')
                value = float(value)
                lo, hi = f.metadata['min'], f.metadata['max']
                if (lo is not None and value < lo) or (hi is not None and value > hi):
                    raise ConfigError(f'ekf_node: parameter {name!r} = {value} outside '
                                      f'[{lo}, {hi}]')
            else:
                value = str(value)
            values[f.name] = value
        return cls(**values)

    def sensor_enabled(self, sensor: str) -> bool:
        """Whether ``sensor`` (one of SENSORS) is fused."""
        return getattr(self, f'use_{sensor}')

    def gate(self, sensor: str) -> float:
        """Mahalanobis rejection distance of ``sensor``."""
        return getattr(self, f'gate_{sensor}', math.inf)


def setting_specs() -> list[tuple[str, str, float | None, float | None]]:
    """(parameter name, description, min, max) of every setting, for ParamSpec."""
    return [(f.metadata['name'], f.metadata['description'], f.metadata['min'],
             f.metadata['max']) for f in fields(EkfSettings)]
