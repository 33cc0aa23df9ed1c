"""ekf_node's schedule, ROS-free: what it does on each input and on each timer tick.

ekf_node, the offline replay (replay_adapters), the golden-bag generator and the
in-process stack harness (dukw_bringup.stack_harness) all drive this runner, so the
estimator's timing rule lives here and nowhere else:

- every sensor sample goes to the estimator as it arrives;
- odometry/filtered goes out with every estimate; /tf and traction at most
  ``tf_rate_hz`` / ``traction_rate_hz`` (their readers need less: README "Topic contract");
- with ``publish_on_imu`` the estimate goes out after each IMU sample (the IMU's rate is
  the output rate: the controller steps on it), and the ``rate_hz`` timer publishes only
  while the IMU has been silent for 1.5 periods, predicting to the present but never
  further than ``sensor_timeout_s`` past the last sample.

The estimate is read through pure queries (odometry(), traction()): asking for it changes
nothing.
"""
from __future__ import annotations

import weakref
from typing import Any, Callable, Mapping

from dukw_common.config import ParamValue
from dukw_common.rates import Decimator
from dukw_common.vehicle import Vehicle, soil_params
from dukw_estimation.estimator import Estimator
from dukw_estimation.samples import OdometryEstimate, TractionEstimate
from dukw_estimation.settings import EkfSettings

#: the timer publishes when the IMU has been silent this many periods
SILENT_PERIODS = 1.5

#: subscribed topic -> the estimator's input method
INPUTS = {'imu/data': 'add_imu', 'gps/fix': 'add_gps_fix', 'gps/vel': 'add_gps_velocity',
          'water/contact': 'add_water_contact', 'depth': 'add_depth',
          'tracks/status': 'add_tracks', 'props/status': 'add_props'}


class Estimate:
    """What ekf_node publishes at once: odometry/filtered always; /tf and traction when
    their observers' rates (``tf_rate_hz``, ``traction_rate_hz``) say so.

    The traction is read from the estimator when first asked for (``traction_query``): a
    composed process hands the odometry to the controller and gets the command out before
    it, and a traction nobody reads (not due, no listener) costs nothing. The runner that
    made the estimate reads it before its estimator takes anything new while the estimate
    is still held (EkfRunner.seal), so the value is the one of the estimate's instant.
    """

    __slots__ = ('odometry', 'tf_due', 'traction_due', '_traction', '_query', '__weakref__')

    def __init__(self, odometry: OdometryEstimate, traction: TractionEstimate | None = None,
                 tf_due: bool = True, traction_due: bool = True, *,
                 traction_query: Callable[[], TractionEstimate] | None = None) -> None:
        if (traction is None) == (traction_query is None):
            raise ValueError('Estimate: give either the traction or the query for it')
        self.odometry = odometry
        self.tf_due = tf_due
        self.traction_due = traction_due
        self._traction = traction
        self._query = traction_query

    @property
    def traction(self) -> TractionEstimate:
        """The traction estimate at the estimate's instant."""
        self.fix_traction()
        return self._traction

    def fix_traction(self) -> None:
        """Read the traction now (before the estimator changes)."""
        if self._traction is None:
            self._traction, self._query = self._query(), None

    @property
    def t_s(self) -> float:
        return self.odometry.t_s


class EkfRunner:
    """ekf_node's schedule around dukw_estimation.estimator.Estimator."""

    def __init__(self, estimator: Estimator, settings: EkfSettings,
                 publish_on_imu: bool, tf_rate_hz: float | None = None,
                 traction_rate_hz: float | None = None) -> None:
        """A rate None: with every estimate."""
        self.estimator = estimator
        self.settings = settings
        self.rate_hz = float(settings.rate_hz)
        self.period_s = 1.0 / self.rate_hz
        self.publish_on_imu = bool(publish_on_imu)
        self.last_event_publish_s = -float('inf')
        self._routes = {topic: getattr(estimator, name) for topic, name in INPUTS.items()}
        self._tf_due = Decimator(tf_rate_hz).due if tf_rate_hz else None
        self._traction_due = Decimator(traction_rate_hz).due if traction_rate_hz else None
        self._last: weakref.ref[Estimate] | None = None     # the last estimate out

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue], vehicle: Vehicle | None = None,
                    settings: EkfSettings | None = None) -> 'EkfRunner':
        """As ekf_node configures it; ``vehicle``/``settings`` override the parameters'
        (the harness hands the simulator's survey datum, a campaign a mismatched beach)."""
        settings = settings or EkfSettings.from_params(params)
        estimator = Estimator(vehicle or Vehicle.from_params(params), settings,
                              soil_params(params, settings.soil_preset or None))
        return cls(estimator, settings, bool(params.get('publish_on_imu', False)),
                   params.get('tf_rate_hz'), params.get('traction_rate_hz'))

    def on_sample(self, topic: str, sample: Any, now_s: float) -> Estimate | None:
        """A converted sample of subscribed ``topic``; the estimate when it goes out now."""
        add = self._routes.get(topic)
        if add is None:
            raise ValueError(f'ekf: no input {topic!r}; inputs are {sorted(INPUTS)}')
        self.seal()
        add(sample)
        if topic != 'imu/data' or not self.publish_on_imu or self.estimator.t_s is None:
            return None
        self.last_event_publish_s = now_s
        return self._publication()

    def tick(self, now_s: float) -> Estimate | None:
        """The timer: publish only while the IMU is silent (and once something arrived)."""
        est = self.estimator
        if est.t_s is None or now_s - self.last_event_publish_s < SILENT_PERIODS * self.period_s:
            return None
        self.seal()
        if 0.0 < now_s - est.t_s <= self.settings.sensor_timeout_s:
            est.advance(now_s)       # predict to the present, never further than a timeout
        return self._publication()

    def _publication(self) -> Estimate:
        odometry = self.estimator.odometry()
        t_s = odometry.t_s
        estimate = Estimate(odometry, None,
                            self._tf_due is None or self._tf_due(t_s),
                            self._traction_due is None or self._traction_due(t_s),
                            traction_query=self.estimator.traction)
        self._last = weakref.ref(estimate)
        return estimate

    def seal(self) -> None:
        """Read the last estimate's traction now if it is still held and unread: call
        before changing the estimator other than through this runner (e.g. set_pose)."""
        last, self._last = self._last, None
        held = last() if last is not None else None
        if held is not None:
            held.fix_traction()

    def estimate(self) -> Estimate:
        """The current estimate (pure: asking changes nothing)."""
        return Estimate(self.estimator.odometry(), self.estimator.traction())
