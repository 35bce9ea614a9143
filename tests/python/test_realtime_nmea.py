"""Real clients read the NMEA 0183 that `shipsim run` sends (systems/hil_heading.toml, loopback,
ports chosen by the OS, every run under a time limit):

- pynmea2 parses every sentence, checksums included;
- gpsd, started here on loopback, reads our UDP NMEA, and `gpspipe -w` reports the latitude,
  longitude, course and speed that the run's CSV implies at the same simulated time, within the
  sentences' precision. Without gpsd (or pynmea2) a test says in one line what it did not check
  and how to install it (and fails with CI=true).

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import csv
import json
import math
import os
import shutil
import socket
import subprocess
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = os.environ.get("SHIPSIM_BIN", str(ROOT / "target" / "release" / "shipsim"))
FMUS = Path(os.environ.get("SHIPSIM_FMU_DIR", str(ROOT / "target" / "fmu")))
A, F = 6378137.0, 1 / 298.257223563


def free_port(kind=socket.SOCK_DGRAM):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def hil(tmp, out_port, in_port):
    text = (ROOT / "systems" / "hil_heading.toml").read_text()
    text = text.replace("../target/fmu/", f"{FMUS}/")
    text = text.replace("127.0.0.1:10110", f"127.0.0.1:{out_port}")
    text = text.replace("127.0.0.1:10111", f"127.0.0.1:{in_port}")
    text = text.replace("../target/demo/hil_heading.csv", "hil.csv")
    p = tmp / "hil.toml"
    p.write_text(text)
    return p


def run(tmp, system, factor, stop):
    return subprocess.run(
        [BIN, "run", str(system), "--real-time-factor", str(factor), "--stop-time", str(stop)],
        cwd=tmp, capture_output=True, text=True, timeout=120,
    )


def missing(msg):
    """A missing tool: one line of what was not checked and how to get it; a failure in CI."""
    if os.environ.get("CI") == "true":
        pytest.fail(msg)
    print(msg)
    pytest.skip(msg)


def test_pynmea2_parses_every_sentence(tmp_path):
    try:
        import pynmea2
    except ImportError:
        missing("pynmea2 missing: not checked that pynmea2 parses every NMEA sentence we send "
                "(pip install pynmea2==1.19.0, tests/python/requirements.txt)")
    out_port = free_port()
    system = hil(tmp_path, out_port, free_port())
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.bind(("127.0.0.1", out_port))
    rx.settimeout(0.2)
    got = []
    done = threading.Event()

    def receive():
        while not done.is_set():
            try:
                got.append(rx.recv(65536).decode("ascii"))
            except socket.timeout:
                pass

    t = threading.Thread(target=receive)
    t.start()
    r = run(tmp_path, system, 20, 30)
    time.sleep(0.3)
    done.set()
    t.join()
    assert r.returncode == 0, r.stderr
    kinds = {}
    for d in got:
        for line in d.split("\r\n"):
            if not line:
                continue
            try:
                kind = pynmea2.parse(line, check=True).sentence_type  # raises on a bad checksum
            except pynmea2.SentenceTypeError:
                # pynmea2 has no class for THS: its frame and checksum are checked by pynmea2's
                # own checksum function.
                body, _, sum_ = line[1:].partition("*")
                assert int(sum_, 16) == pynmea2.NMEASentence.checksum(body), line
                kind = body[2:5]
                assert kind == "THS", line
            kinds[kind] = kinds.get(kind, 0) + 1
    assert set(kinds) == {"HDT", "THS", "ROT", "RSA", "HDG", "GGA", "RMC", "VTG", "VHW"}, kinds
    assert all(n >= 30 for n in kinds.values()), kinds


def plane(lat0, lon0, north, east):
    """The datum conversion of master/src/realtime/nmea/datum.rs."""
    e2 = F * (2 - F)
    s = math.sin(math.radians(lat0))
    w = math.sqrt(1 - e2 * s * s)
    m, n = A * (1 - e2) / w**3, A / w
    return (lat0 + math.degrees(north / m),
            lon0 + math.degrees(east / (n * math.cos(math.radians(lat0)))))


def test_gpsd_reads_our_nmea(tmp_path):
    gpsd, gpspipe = shutil.which("gpsd") or shutil.which("gpsd", path="/usr/sbin"), shutil.which("gpspipe")
    if not (gpsd and gpspipe):
        missing("gpsd/gpspipe missing: not checked that gpsd reads our UDP NMEA and reports the CSV's "
                "lat/lon/course/speed (apt-get install gpsd gpsd-clients)")
    out_port, gpsd_port = free_port(), free_port(socket.SOCK_STREAM)
    system = hil(tmp_path, out_port, free_port())
    daemon = subprocess.Popen([gpsd, "-N", "-n", "-G", "-S", str(gpsd_port), f"udp://127.0.0.1:{out_port}"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        time.sleep(1.0)
        pipe = subprocess.Popen([gpspipe, "-w", f"127.0.0.1:{gpsd_port}"], stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, text=True)
        r = run(tmp_path, system, 1, 12)
        time.sleep(1.0)
        pipe.terminate()
        out, _ = pipe.communicate(timeout=10)
    finally:
        daemon.terminate()
        daemon.wait(timeout=10)
    assert r.returncode == 0, r.stderr
    tpv = [j for j in map(json.loads, filter(None, out.splitlines())) if j.get("class") == "TPV" and "lat" in j and "time" in j]
    assert len(tpv) >= 5, out[-2000:]
    with open(tmp_path / "hil.csv") as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    by_time = {round(row["time"], 6): i for i, row in enumerate(rows)}
    checked = 0
    for j in tpv:
        hms = j["time"].split("T")[1].rstrip("Z")
        h, m, s = hms.split(":")
        t = round(int(h) * 3600 + int(m) * 60 + float(s) - 12 * 3600, 6)
        i = by_time.get(t)
        if i is None or i == 0:
            continue
        row, prev = rows[i], rows[i - 1]
        lat, lon = plane(63.44, 10.30, row["ship.x"], row["ship.y"])
        dn, de = row["ship.x"] - prev["ship.x"], row["ship.y"] - prev["ship.y"]
        dt = row["time"] - prev["time"]
        course = math.degrees(math.atan2(de, dn)) % 360
        speed = math.hypot(dn, de) / dt
        assert abs(j["lat"] - lat) < 2e-7 and abs(j["lon"] - lon) < 2e-7, (j, lat, lon)
        if "track" in j:
            assert abs((j["track"] - course + 180) % 360 - 180) < 0.011, (j, course)
        if "speed" in j:
            assert abs(j["speed"] - speed) < 0.006, (j, speed)  # 0.01 kn
        checked += 1
    assert checked >= 5, (checked, tpv[:3])
