"""Ctrl-C: SIGINT during a long design stops it promptly with KeyboardInterrupt, and the next
design runs normally."""
import os
import signal
import threading
import time

import pytest

import hinfix


@pytest.fixture(autouse=True)
def python_handles_sigint():
    """Python's own SIGINT handler (KeyboardInterrupt), whatever the process inherited: a shell
    starts background jobs with SIGINT ignored, and Python then installs no handler."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def send_sigint_after(seconds):
    t = threading.Timer(seconds, os.kill, args=(os.getpid(), signal.SIGINT))
    t.start()
    return t


def test_sigint_stops_a_long_design_promptly():
    P, nmeas, ncon = hinfix.load_plant("AC8")
    timer = send_sigint_after(0.5)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        hinfix.design(P, nmeas, ncon, 3, cpumax=20.0)  # 20 CPU s if not stopped
    elapsed = time.monotonic() - start
    timer.join()
    assert elapsed < 3.0, elapsed
    # the flag was this call's: the next design is not cancelled
    _, info = hinfix.design(P, nmeas, ncon, 0, maxevals=100)
    assert info.status != "interrupted"


def test_sigint_stops_a_campaign_and_it_resumes(tmp_path):
    campaign = tmp_path / "long.toml"
    campaign.write_text('name = "long"\n[defaults]\ncpumax = 20.0\nthreads = 1\n'
                        '[[problem]]\nplant = "AC8"\norders = [3]\n')
    timer = send_sigint_after(0.5)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        hinfix.run_campaign(campaign, tmp_path / "results", progress=False)
    assert time.monotonic() - start < 5.0
    timer.join()
    # an interrupted job is not journaled
    assert len(hinfix.read_results(tmp_path / "results" / "long")) == 0


def test_other_threads_run_during_a_design():
    """The GIL is released while the design runs: a Python thread keeps ticking."""
    P, nmeas, ncon = hinfix.load_plant("AC8")
    ticks, stop = [], threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.005)

    t = threading.Thread(target=tick)
    t.start()
    start = time.monotonic()
    hinfix.design(P, nmeas, ncon, 2, cpumax=0.5)  # half a CPU second
    end = time.monotonic()
    stop.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert len(during) >= 20, (len(during), end - start)
