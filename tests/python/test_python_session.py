"""Stepping sessions from Python (`System.start`, issue 37).

- a session that only reads equals `System.run` bit for bit (RRS: multi-rate; Jacobi and
  Gauss-Seidel; the autopilot system with its 1 s heading sensor);
- a value set between steps equals the same change written as an event in the system file,
  bit for bit (a tunable Integer, a Real given in degrees);
- checkpoint and restore rewind the session, which continues bit for bit as a run without
  what was undone;
- the journal replays bit for bit (`System.replay` and `shipsim replay`);
- misuse raises its exception (VariableError, SessionError), never a crash or a hang;
- Ctrl-C stops a long advance, and the session goes on from where it stopped.

Tolerance: none; arrays are compared as bit patterns."""
import csv
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import shipsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
RRS = ROOT / "systems" / "rrs.toml"
AUTOPILOT = ROOT / "systems" / "autopilot_current.toml"


def bits(df):
    """A frame as one uint64 array of its time and columns' bit patterns."""
    cols = [df.index.to_numpy(dtype=np.float64)] + [df[c].to_numpy(dtype=np.float64) for c in df.columns]
    return np.stack(cols).view(np.uint64)


def same(a, b):
    assert list(a.columns) == list(b.columns)
    assert len(a) == len(b)
    assert np.array_equal(bits(a), bits(b))


def with_events(tmp_path, system, events):
    """A copy of `system` in `tmp_path` (FMU paths made absolute) with `events` appended:
    [(time, "inst.var", value text)]."""
    text = system.read_text()
    text = text.replace('"../target/', f'"{ROOT}/target/')
    for t, name, value in events:
        text += f'\n[[events]]\ntime = {t!r}\nset = "{name}"\nvalue = {value}\n'
    p = tmp_path / f"events_{len(events)}.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize(
    "system, algorithm, stop",
    [(RRS, None, 60.0), (RRS, "gauss-seidel", 60.0), (AUTOPILOT, None, 120.0)],
)
def test_a_session_that_only_reads_is_the_run(system, algorithm, stop):
    s = shipsim.System.load(system)
    ref = s.run(stop_time=stop, algorithm=algorithm)
    with s.start(stop_time=stop, algorithm=algorithm) as session:
        n = 1
        while session.state == "open":
            session.step(n)
            session.get(ref.columns[0])
            n = n % 17 + 1
        assert session.time == stop
        same(session.rows(), ref)


def test_a_value_set_between_steps_is_the_same_change_as_an_event(tmp_path):
    evented = with_events(tmp_path, RRS, [(12.5, "autopilot.roll_mode", "0"), (20.0, "autopilot.angle_max", '"20 deg"')])
    ref = shipsim.System.load(evented).run(stop_time=40)
    s = shipsim.System.load(RRS)
    with s.start(stop_time=40) as session:
        session.advance_to(12.5)
        session.set("autopilot.roll_mode", 0)
        session.advance_to(20.0)
        session.set("autopilot.angle_max", "20 deg")
        session.step()
        assert session.get("autopilot.angle_max") == np.deg2rad(20.0)
        assert session.get("autopilot.roll_mode") == 0
        session.advance_to(40)
        same(session.rows(), ref)
    # and the sets did something
    assert not np.array_equal(bits(ref), bits(s.run(stop_time=40)))


def test_checkpoint_and_restore_rewind_the_session(tmp_path):
    s = shipsim.System.load(RRS)
    plain = s.run(stop_time=30)
    changed = shipsim.System.load(with_events(tmp_path, RRS, [(10.0, "autopilot.roll_mode", "0")])).run(stop_time=30)
    with s.start(stop_time=30) as session:
        session.advance_to(10)
        cp = session.checkpoint()
        assert (cp.time, cp.step) == (10.0, 200)
        session.set("autopilot.roll_mode", 0).advance_to(30)
        same(session.rows(), changed)
        assert session.state == "ended"
        session.restore(cp)
        assert session.time == 10.0 and session.state == "open" and len(session.rows()) == 201
        session.advance_to(30)
        same(session.rows(), plain)
        session.restore(cp).set("autopilot.roll_mode", 0).advance_to(30)
        same(session.rows(), changed)
        # the master checkpoint as a file: `shipsim run --resume` continues the plain run
        session.restore(cp)
        cp.save(tmp_path / "cp.bin")
    out = tmp_path / "tail.csv"
    subprocess.run([BIN, "run", str(RRS), "-q", "--stop-time", "30", "--resume", str(tmp_path / "cp.bin"), "-o", str(out)], check=True)
    with open(out, newline="") as f:
        rows = list(csv.reader(f))[1:]
    assert float(rows[0][0]) == 10.0
    tail = np.array([[float(x) for x in r] for r in rows])
    assert np.array_equal(tail.view(np.uint64), bits(plain)[:, 200:].T)


def test_the_journal_replays_bit_for_bit(tmp_path):
    journal = tmp_path / "session.jsonl"
    s = shipsim.System.load(RRS)
    s.set("waves.seed", 11)
    session = s.start(stop_time=30, variables=["ship.*", "autopilot.*"], journal=journal)
    session.advance_to(5)
    session.set("autopilot.angle_max", "25 deg")
    cp = session.checkpoint()
    session.step(40)
    session.set("autopilot.roll_mode", 0)
    session.step(100)
    session.restore(cp)
    for k in range(50):
        session.set("autopilot.lambda", 2.0 + 0.1 * np.sin(k))  # a controller writing every step
        session.step()
    rows = session.rows()
    assert session.journal_path == str(journal)
    del session  # not closed: collected, its journal ended where it stood
    import gc

    gc.collect()
    text = journal.read_text().splitlines()
    assert text[-1] == '{"record":"end","step":150}'
    replayed = shipsim.System.replay(journal)
    assert replayed.index[-1] == 7.5
    same(replayed, rows)
    # the command line gives the same numbers
    out = tmp_path / "replay.csv"
    subprocess.run([BIN, "replay", str(journal), "-o", str(out)], check=True, capture_output=True)
    with open(out, newline="") as f:
        table = list(csv.reader(f))
    assert table[0] == ["time", *rows.columns]
    cli = np.array([[float(x) for x in r] for r in table[1:]])
    assert np.array_equal(cli.view(np.uint64), bits(rows).T)


def test_journal_text_replays_an_open_session(tmp_path):
    s = shipsim.System.load(AUTOPILOT)
    with s.start(stop_time=100) as session:
        session.advance_to(20)
        session.set("ap.heading_reference", "10 deg")
        session.advance_to(60)
        session.save_journal(tmp_path / "j.jsonl")
        same(shipsim.System.replay(tmp_path / "j.jsonl"), session.rows())


def test_misuse_raises_its_exception():
    s = shipsim.System.load(RRS)
    session = s.start(stop_time=5)
    session.step(2)
    with pytest.raises(shipsim.VariableError, match="'autopilot.k_dp0' is fixed parameter; only inputs and tunable parameters"):
        session.set("autopilot.k_dp0", 0.0)
    with pytest.raises(shipsim.VariableError, match="is an Integer; give a whole number"):
        session.set("autopilot.roll_mode", 0.5)
    with pytest.raises(shipsim.VariableError, match="autopilot.angle_max"):
        session.set("autopilot.angle_max", "3 m")
    with pytest.raises(shipsim.VariableError, match="outside the declared range"):
        session.set("autopilot.roll_mode", 99)
    with pytest.raises(shipsim.VariableError, match="did you mean"):
        session.get("autopilot.rol_mode")
    with pytest.raises(shipsim.SessionError, match="communication point"):
        session.advance_to(1.234)
    with pytest.raises(ValueError):
        session.step(-1)
    other = s.start(stop_time=5)
    with pytest.raises(shipsim.SessionError, match="taken by another session"):
        session.restore(other.checkpoint())
    other.close()
    session.advance_to(5)
    with pytest.raises(shipsim.SessionError, match="at the end of the run"):
        session.step()
    session.close()
    session.close()
    for call in (session.step, lambda: session.set("autopilot.roll_mode", 0), lambda: session.get("ship.roll"), session.checkpoint):
        with pytest.raises(shipsim.SessionError, match="it is closed"):
            call()


def test_two_threads_stepping_one_session():
    # A long advance in one thread (about a second: 600,000 macro steps of RRS); the main
    # thread's calls meanwhile fail at once with SessionError, never wait for it.
    s = shipsim.System.load(RRS)
    with s.start(stop_time=30000, variables=[]) as session:
        errors, started = [], threading.Event()

        def stepper():
            started.set()
            session.advance_to(30000)

        t = threading.Thread(target=stepper)
        t.start()
        started.wait()
        time.sleep(0.1)  # the advance holds the session from its first instant
        begin = time.perf_counter()
        while t.is_alive() and not errors:
            try:
                session.step()
            except shipsim.SessionError as e:
                errors.append((str(e), time.perf_counter() - begin))
        t.join()
        assert errors, "the other thread's advance ended before a call could meet it"
        message, waited = errors[0]
        assert "being stepped by another thread" in message
        assert session.time == 30000.0


def test_ctrl_c_stops_a_long_advance_and_the_session_goes_on():
    script = textwrap.dedent(
        f"""
        import shipsim
        s = shipsim.System.load({str(RRS)!r})
        with s.start(stop_time=1e6, variables=["ship.roll"]) as session:
            print("started", flush=True)
            try:
                session.advance_to(1e6)
                print("finished", flush=True)
            except KeyboardInterrupt:
                t = session.time
                print("interrupted", t > 0, session.state, flush=True)
                session.step(3)
                print("stepped", round(session.time - t, 6), len(session.rows()) == session.step_index + 1, flush=True)
        """
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "started"
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert out.splitlines() == ["interrupted True open", "stepped 0.15 True"], (out, err)


def test_a_failed_session_raises_and_refuses_to_go_on(tmp_path):
    from test_python_isolation import c_fmu

    c_fmu(tmp_path, "testfmu", "testfmu.c")
    system = tmp_path / "fail.toml"
    system.write_text(
        '[simulation]\nstop_time = 1.0\nstep_size = 0.1\n[[instances]]\nname = "m"\n'
        'fmu = "testfmu.fmu"\nparameters = { u = 1.0, fail_at_step = 3 }\n'
    )
    session = shipsim.System.load(system).start()
    session.step(2)
    with pytest.raises(shipsim.SimulationError, match="fmi2DoStep") as e:
        session.step(5)
    assert e.value.instance == "m" and e.value.function == "fmi2DoStep"
    assert session.state == "failed" and "fmi2DoStep" in session.reason
    for call in (session.step, lambda: session.set("m.u", 2.0), lambda: session.get("m.y")):
        with pytest.raises(shipsim.SessionError, match="it failed"):
            call()
    session.close()
    assert session.state == "closed"


def test_an_isolated_session_is_the_run():
    s = shipsim.System.load(RRS)
    ref = s.run(stop_time=20)
    with s.start(stop_time=20, isolate=["autopilot", "gear"]) as session:
        while session.state == "open":
            session.set("autopilot.roll_mode", 1)  # its value already: the same bits
            session.step(7)
        same(session.rows(), ref)
