# SPDX-License-Identifier: MIT
"""Issue 41 item 4: an encode can be watched and cancelled from Python.

cbrdf.encode runs on the calling thread with the GIL released; the encoder's progress callback
(at least every 50 ms of work) takes the GIL back to handle signals and to call progress=. Ctrl-C
(here _thread.interrupt_main from a timer thread, the same pending SIGINT) must raise
KeyboardInterrupt promptly and leave no thread behind: the old runner left the interrupted fit
running on a detached thread.

The aim is 100 ms; cbrdf_encode_bench's BM_CancelLatency measures it. An idle machine gives
10-60 ms, but CI's 2 cores busy with ctest -j2 have given 123-147 ms, so these tests hold the
bound the C++ tests hold (CANCEL_BOUND, three times the aim): a checkpoint missing from a loop
shows as seconds, not as tens of milliseconds.
"""
import _thread
import os
import threading
import time

import pytest

import cbrdf

STAGES = {"fit", "bits", "residual", "target"}
CANCEL_BOUND = 0.3  # seconds; tests/encoder/encode_progress_test.cc's kCancelBoundMs


def os_threads():
    """The process's threads, the library's pool and any detached std::thread included."""
    return len(os.listdir("/proc/self/task"))


@pytest.fixture(scope="module")
def table(work):
    t = cbrdf.read_merl(work / "plastic.binary")
    cbrdf.encode(t, slices=1, bits=8)  # the library's thread pool exists before threads are counted
    return t


def interrupted_encode(table):
    """Seconds from Ctrl-C (sent 0.2 s into a target_psnr=60 encode) to KeyboardInterrupt."""
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        _thread.interrupt_main()

    timer = threading.Timer(0.2, interrupt)

    def started(fraction, stage):
        if not timer.is_alive() and not sent:
            timer.start()  # once the encoder is at work

    try:
        with pytest.raises(KeyboardInterrupt):
            cbrdf.encode(table, target_psnr=60, progress=started)
        return time.monotonic() - sent[0]
    finally:
        timer.cancel()
        timer.join()


def test_ctrl_c_stops_a_target_encode_promptly_and_leaves_no_thread(table):
    python_threads, threads = threading.active_count(), os_threads()
    # The median of three: one run slowed by a loaded machine does not decide it.
    latencies = sorted(interrupted_encode(table) for _ in range(3))
    print("KeyboardInterrupt after " + ", ".join(f"{x * 1e3:.1f}" for x in latencies) + " ms")
    assert latencies[1] < CANCEL_BOUND and latencies[2] < 0.5, latencies
    assert threading.active_count() == python_threads
    assert os_threads() == threads


def test_progress_is_called_in_order_and_false_cancels(table):
    seen = []

    def watch(fraction, stage):
        seen.append((fraction, stage))

    data = cbrdf.encode(table, slices=1, bits=8, progress=watch)
    assert data == cbrdf.encode(table, slices=1, bits=8)  # watching changes nothing
    assert seen and {s for _, s in seen} <= STAGES
    known = [f for f, _ in seen if f >= 0]
    assert known == sorted(known) and all(0 <= f <= 1 for f in known)

    calls = []

    def stop(fraction, stage):
        calls.append(time.monotonic())
        return False

    with pytest.raises(cbrdf.Error) as e:
        cbrdf.encode(table, target_psnr=60, progress=stop)
    assert e.value.code == cbrdf.ErrorCode.CANCELLED and e.value.code_name == "cancelled"
    assert len(calls) == 1  # the first False stops it
    assert time.monotonic() - calls[0] < CANCEL_BOUND
    assert str(e.value) == "cancelled"


def test_encode_errors_start_with_the_path_as_the_commands_do(work):
    path = str(work / "plastic.binary")
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.encode(path, slices=1, bits=8, progress=lambda fraction, stage: False)
    assert str(e.value) == f"{path}: cancelled"


def test_an_exception_from_progress_propagates(table):
    class Stop(Exception):
        pass

    def fail(fraction, stage):
        raise Stop(stage)

    with pytest.raises(Stop):
        cbrdf.encode(table, slices=1, bits=8, progress=fail)

    def wrong(fraction, stage):
        raise TypeError("the caller's own")

    # Exactly the caller's exception: not turned into cbrdf.ArgumentTypeError like a bad argument.
    with pytest.raises(TypeError) as e:
        cbrdf.encode(table, slices=1, bits=8, progress=wrong)
    assert type(e.value) is TypeError and str(e.value) == "the caller's own"
    # None and True go on.
    assert cbrdf.encode(table, slices=1, bits=8, progress=lambda f, s: None)
    assert cbrdf.encode(table, slices=1, bits=8, progress=lambda f, s: True)
