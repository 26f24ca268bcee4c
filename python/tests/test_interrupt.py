"""Ctrl-C during a run (the notebook's stop button): `Interrupted`, itself a KeyboardInterrupt,
with nothing returned or written; the package works on afterwards."""

import os
import signal
import threading

import pytest

import stf_lab

EXP = "experiments/power_law_fit.toml"


@pytest.fixture
def sigint_raises():
    """Python's own SIGINT handler for the test: a process started in the background (`cmd &`,
    as a CI script may start the tests) inherits SIGINT ignored, and Python then installs no
    handler, so the signal would never reach the run."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def test_a_sigint_during_a_run_raises_interrupted(repo, sigint_raises):
    sent = []

    def progress(status, elapsed):
        if not sent:  # the first call, as the run starts: interrupt from another thread
            sent.append(status)
            threading.Thread(target=os.kill, args=(os.getpid(), signal.SIGINT)).start()

    # A discovery (seconds long), so the signal surely arrives while it runs.
    with pytest.raises(stf_lab.Interrupted) as e:
        stf_lab.discover("experiments/discovery.toml", progress=progress)
    assert isinstance(e.value, KeyboardInterrupt)
    assert "nothing was written" in str(e.value)
    assert sent


def test_a_keyboard_interrupt_in_the_progress_callback_stops_the_run(repo):
    def progress(status, elapsed):
        raise KeyboardInterrupt

    with pytest.raises(stf_lab.Interrupted):
        stf_lab.fit(EXP, progress=progress)
    # The lab is usable after an interrupt.
    assert len(stf_lab.simulate(EXP)) == 12001


def test_progress_reports_what_the_run_does(repo):
    # A discovery (seconds long): the status is sampled every 0.1 s, so a fit of a few tenths
    # of a second may show only its start on a busy machine.
    seen = []
    stf_lab.discover(
        "experiments/discovery.toml",
        progress=lambda status, elapsed: seen.append((status, elapsed)),
    )
    assert seen and all(e >= 0 for _, e in seen)
    assert seen[0][0] == "starting"
    assert any(s.startswith("discover  ") and "candidate" in s for s, _ in seen), seen
