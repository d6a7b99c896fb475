"""Regression: an FMU that logs after fmpy.simulate_fmu has returned must not call the
logger simulate_fmu freed (fmpy's logger proxy has one process-global target). That
use-after-free crashed the test process with a segfault inside fmi2DoStep; the check runs
in a subprocess so a crash fails this test instead of ending the session."""

import subprocess
import sys
import textwrap

from fmu_util import fmu_path

SCRIPT = textwrap.dedent(
    """
    import gc, math, sys
    from fmpy import simulate_fmu
    from tailsim import Fmu, fmilog

    stale = []
    simulate_fmu({plant!r}, stop_time=0.01, logger=lambda *a: stale.append(a))
    gc.collect()

    routed = []
    fmu = Fmu({sensors!r}, {tmp!r})
    fmilog.route("after-simulate", lambda status, category, message: routed.append((status, message)))
    s = fmu.instantiate("after-simulate")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    fmu.set(s, {{"quat_1": 0.0, "quat_2": 0.0, "quat_3": 0.0, "quat_4": 0.0}})
    try:
        s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.005)
    except Exception:
        pass
    print(len(stale), len(routed), routed[-1][1] if routed else "")
    """
)


def test_an_fmu_logging_after_simulate_fmu_reaches_a_live_logger(tmp_path):
    script = SCRIPT.format(
        plant=str(fmu_path("tailsitter_plant")),
        sensors=str(fmu_path("tailsitter_sensors")),
        tmp=str(tmp_path),
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    stale, routed, last = out.stdout.split(maxsplit=2)
    assert stale == "0", "the freed simulate_fmu logger was called after simulate_fmu returned"
    assert int(routed) >= 1 and "quaternion" in last, out.stdout
