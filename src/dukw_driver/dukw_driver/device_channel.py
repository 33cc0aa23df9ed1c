"""One serial device as a node sees it: link, decoder and health together. ROS-free.

``poll(now_s)`` reads what the device sent, decodes it and keeps the device's
``DeviceHealth`` (message rate, parse errors) in step with the decoder's
counters; ``status(now_s)`` is the Health for /diagnostics, with the decoder's
own counters added.
"""
from __future__ import annotations

from dataclasses import asdict
from typing import Callable, Protocol

from dukw_common.config import ConfigError
from dukw_common.diagnostics import Health
from dukw_driver.serial_link import DeviceHealth, SerialLink, validate_baud, validate_port


class Counters(Protocol):
    """What a decoder counts: good messages and errors (plus its own details)."""

    @property
    def messages(self) -> int: ...

    @property
    def errors(self) -> int: ...


class DeviceChannel:
    """A SerialLink, the function that decodes its bytes, and the device's health."""

    def __init__(self, link: SerialLink, decode: Callable[[bytes, float], list],
                 counters: Counters, health: DeviceHealth) -> None:
        self.link = link
        self.decode = decode
        self.counters = counters
        self.health = health
        self._counted = 0

    def poll(self, now_s: float) -> list:
        """Read and decode what arrived; return the decoded items (never raises)."""
        items = self.decode(self.link.poll(), now_s)
        for _ in range(self.counters.messages - self._counted):
            self.health.message(now_s)
        self._counted = self.counters.messages
        self.health.parse_errors = self.counters.errors
        return items

    def status(self, now_s: float) -> Health:
        """The device's Health now; the decoder's own counters added (parse_errors: all errors)."""
        health = self.health.health(self.link, now_s)
        health.values.update({k: v for k, v in asdict(self.counters).items()
                              if isinstance(v, int) and k not in health.values})
        return health

    def close(self) -> None:
        """Release the serial device."""
        self.link.close()


def require_name(value: object, name: str) -> str:
    """Return ``value`` if it is a non-empty name (e.g. a frame id); else ConfigError naming it."""
    if not isinstance(value, str) or not value.strip() or value != value.strip():
        raise ConfigError(f'parameter {name!r} must be a non-empty name without spaces, '
                          f'got {value!r}')
    return value


def link_from_params(params: dict, device: str) -> SerialLink:
    """A SerialLink on ``<device>.port`` at ``<device>.baud``; ConfigError naming a bad one."""
    port = validate_port(params[f'{device}.port'], f'{device}.port')
    return SerialLink(port, validate_baud(params[f'{device}.baud'], f'{device}.baud'))
