"""cProfile a call and keep the statistics as text (benchmarks/profiles/), for the benchmarks'
``--profile FILE`` options."""
from __future__ import annotations

import cProfile
import io
import os
import pstats
import time
from pathlib import Path
from typing import Any, Callable


def profile_to_text(call: Callable[[], Any], path: str | Path, header: str) -> Any:
    """Run ``call`` under cProfile; write ``header``, the load average and the top entries by
    own and by cumulative time to ``path``; return what ``call`` returned."""
    profile = cProfile.Profile()
    profile.enable()
    try:
        result = call()
    finally:
        profile.disable()
    text = io.StringIO()
    stats = pstats.Stats(profile, stream=text)
    stats.sort_stats('tottime').print_stats(40)
    stats.sort_stats('cumulative').print_stats(40)
    load = ' '.join(f'{x:.2f}' for x in os.getloadavg())
    stamp = time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    lines = [f'# {line}' if line else '#' for line in header.strip().splitlines()]
    lines.append(f'# {stamp}, load average {load} (2-core machine shared by five engineers)')
    base = str(Path(__file__).resolve().parents[1]) + '/'
    Path(path).write_text('\n'.join(lines) + '\n' + text.getvalue().replace(base, ''))
    return result
