"""Make docs/recording.png: a screenshot of rerun's own viewer showing a real recording.

The plate rig (10 degrees of torsion) is simulated for 10 s by every engine, recorded with
:func:`validate.recording.record`, opened in a headless rerun viewer and captured 3 s in. With no GPU
the viewer renders through Mesa's software Vulkan driver (Debian: ``apt-get install
mesa-vulkan-drivers``).

Run: python docs/recording_png.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from rerun.experimental import ViewerClient

from validate.assets import rig
from validate.engines import engines
from validate.recording import TIMELINE, record

OUT = Path(__file__).with_name("recording.png")
DURATION, SHOT_AT = 10.0, 3.0
PORT = 9877  # not rerun's default, so that a viewer the user has open is left alone


def main() -> None:
    plate = rig("plate")
    runs = [run(plate, DURATION, 0.01, 1e-10) for run in engines().values()]
    with tempfile.TemporaryDirectory() as tmp:
        path = record(Path(tmp) / "plate.rrd", "plate, 10 deg torsion: " + ", ".join(r.engine for r in runs), runs)
        with ViewerClient.spawn(headless=True, port=PORT, hide_welcome_screen=True) as viewer:
            viewer.open(str(path))
            deadline = time.monotonic() + 60.0
            while viewer.get_state().loading:
                if time.monotonic() > deadline:
                    raise TimeoutError(f"the viewer is still loading {path} after 60 s")
                time.sleep(0.5)
            viewer.set_time(TIMELINE, duration=SHOT_AT, play_state="paused")
            time.sleep(5.0)  # let start-up notifications fade and the software renderer draw a frame
            viewer.save_screenshot(str(OUT))
            viewer.quit()
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
