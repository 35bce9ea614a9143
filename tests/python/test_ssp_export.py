"""SSP 1.0 export: every system in systems/ exported with `shipsim export-ssp`.

* Each exported SystemStructure.ssd and each .ssv parameter set validates against the SSP 1.0 XML
  schemas that FMPy's wheel ships (fmpy/ssp/schema), read with lxml's XMLSchema.
* Each exportable system, run in libcosim from the .ssp (`CosimExecution.from_ssp_file`, the step
  size from the file's OSP annotation), gives results equal bit for bit (tolerance 0) to
  `shipsim run` of the TOML; the run is cut and recorded as in test_systems_libcosim.py (localise).
* The same .ssp run by shipsim itself (`shipsim run system.ssp`, the SSP importer) gives the
  TOML's results bit for bit; an SSD written here with Integer and Boolean mapping
  transformations, a linear transformation and a String parameter exports and runs back
  unchanged.
* The systems SSP 1.0 cannot express are refused with an error naming what (NOT_EXPORTABLE), and
  no archive is written.
* FMPy (fmpy.ssp, a subset of SSP): it reads every export (components, FMU sources, connections,
  the parameter sets bound to the components) as the TOML says. What FMPy 0.3.32 does not apply
  (docs/ssp.md, "Export"): the parameter bindings (simulate_ssp takes one parameter set as an
  argument and ignores the SSD's bindings), the LinearTransformation (FMPy looks for
  ssd:LinearTransformation, SSP 1.0 puts it in the ssc namespace, so it never finds one), the
  step multiples (an OSP annotation), a Boolean parameter given as text (set to `"false" != 0.0`,
  i.e. true), and its loop steps every FMU with the inputs at 0.0 on the first step (not the
  outputs after initialization) and sums the time step by step. Within that subset (a system
  without gains or step multiples, the archive's parameters passed as FMPy's argument, Booleans
  as Python bools) simulate_ssp runs the export, applies every connection (the end connector
  equals the start connector at every step) and stays within REL_TOL of shipsim; without the
  parameters it does not (current.current_east 0.0 against 2.57 at the first step).

Environment: SHIPSIM_BIN (the master), SHIPSIM_FMU_DIR (our built FMUs).
"""
import csv
import os
import pathlib
import re
import subprocess
import sys
import tomllib
import zipfile

import fmpy
import pytest
from lxml import etree

import test_master_interop
from cosim import variables_by_name
from test_master_interop import assert_same_as_libcosim, read_csv, shipsim
from test_systems_libcosim import SYSTEMS, assert_moves, localise

SCHEMA_DIR = pathlib.Path(fmpy.__file__).parent / "ssp" / "schema"

# Systems SSP 1.0 cannot express: {system file: what the refusal must name}. SSP has no scenario
# form, so a system with [[events]] is refused (export-osp writes them as a libcosim scenario).
# system -> (what is named, why SSP 1.0 cannot express it)
NOT_EXPORTABLE = {
    "dgps_stopping.toml": ("event at t = 60 s setting ship.shaft_speed_command = 1",
                           "SSP 1.0 has no scenario form"),
    "steering_gear_classification.toml": ("event at t = 5 s setting slow.rudder_command",
                                          "SSP 1.0 has no scenario form"),
    "container_ship_seaway_autopilot.toml": ("summed input ship.yaw_moment",
                                             "it has no sum of several"),
}

# The system FMPy's simulate_ssp runs here: no gain or offset on a connection (FMPy ignores the
# LinearTransformation) and no step multiple (FMPy steps every FMU at one step size).
FMPY_SYSTEM = "autopilot_current.toml"
FMPY_STEPS = 200
# FMPy's loop differs from shipsim's (first step with every input at 0.0, time summed step by
# step): |fmpy - shipsim| <= REL_TOL * max(1, |shipsim|) over FMPY_STEPS steps. Measured: 3.2e-3,
# ap.rudder_command at the first step (the autopilot sees heading 0.0 instead of the first noisy
# measurement), smaller afterwards.
REL_TOL = 1e-2

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}


def exportable():
    return sorted(p.name for p in SYSTEMS.glob("*.toml") if p.name not in NOT_EXPORTABLE)


def ids(s):
    return s.removesuffix(".toml")


def export(toml, ssp):
    return shipsim("export-ssp", toml, "-o", ssp)


def toml_connections(spec):
    """(from, to, gain, offset) of the system file's connections, as written."""
    out = []
    for c in spec.get("connections", []):
        if isinstance(c, str):
            f, t = (s.strip() for s in c.split("->"))
            out.append((f, t, 1.0, 0.0))
        else:
            out.append((c["from"], c["to"], c.get("gain", 1.0), c.get("offset", 0.0)))
    return out


def test_not_exportable_list_is_current():
    for system in NOT_EXPORTABLE:
        assert (SYSTEMS / system).exists(), f"{system} is listed as not exportable but is not in systems/"


@pytest.mark.parametrize("system", sorted(NOT_EXPORTABLE), ids=ids)
def test_refused_with_what_ssp_cannot_express(system, tmp_path):
    toml, _ = localise(system, tmp_path)
    ssp = tmp_path / "out.ssp"
    r = shipsim("export-ssp", toml, "-o", ssp, check=False)
    named, why = NOT_EXPORTABLE[system]
    assert r.returncode != 0, f"{system}: export-ssp accepted it ({named})"
    assert named in r.stderr and why in r.stderr, r.stderr
    assert not ssp.exists() and not list(tmp_path.glob("*.partial"))


@pytest.mark.parametrize("old, new, named", [
    ('algorithm = "jacobi"', 'algorithm = "gauss-seidel"', 'algorithm "gauss-seidel": SSP 1.0 has no master algorithm'),
    ('algorithm = "jacobi"', 'algorithm = "jacobi"\nlast_step = "short"\nstop_time = 10.025',
     'stop time 10.025 s is off the base-step grid and last_step = "short"'),
], ids=["gauss-seidel", "short-last-step"])
def test_refused_settings(old, new, named, tmp_path):
    """What the simulation settings ask for and SSP 1.0 cannot say is refused by name."""
    toml, _ = localise(FMPY_SYSTEM, tmp_path)
    text = toml.read_text()
    assert old in text
    text = text.replace(old, new)
    if "stop_time = 10.025" in new:
        text = re.sub(r"(?m)^stop_time\s*=\s*[-+0-9.eE_]+\n", "", text, count=1)
    toml.write_text(text)
    shipsim("check", toml)
    ssp = tmp_path / "out.ssp"
    r = shipsim("export-ssp", toml, "-o", ssp, check=False)
    assert r.returncode != 0 and named in r.stderr, r.stderr
    assert not ssp.exists()


@pytest.mark.parametrize("system", exportable(), ids=ids)
def test_export_is_valid_ssp(system, tmp_path):
    """The SSD and every SSV validate against the SSP 1.0 schemas; every file the SSD references
    is in the archive; each component's parameter set holds the system file's values."""
    toml, spec = localise(system, tmp_path)
    ssp = tmp_path / "out.ssp"
    export(toml, ssp)
    ssd_schema = etree.XMLSchema(file=str(SCHEMA_DIR / "SystemStructureDescription.xsd"))
    ssv_schema = etree.XMLSchema(file=str(SCHEMA_DIR / "SystemStructureParameterValues.xsd"))
    with zipfile.ZipFile(ssp) as z:
        names = set(z.namelist())
        ssd = etree.fromstring(z.read("SystemStructure.ssd"))
        assert ssd_schema.validate(ssd), f"{system}: SystemStructure.ssd: {ssd_schema.error_log}"
        components = ssd.findall("ssd:System/ssd:Elements/ssd:Component", NS)
        assert [c.get("name") for c in components] == [i["name"] for i in spec["instances"]]
        for c, inst in zip(components, spec["instances"]):
            assert c.get("source") in names, f"{system}: {c.get('source')} is not in the archive"
            fmu = tmp_path / os.path.basename(inst["fmu"])
            assert z.read(c.get("source")) == fmu.read_bytes(), f"{system}: {c.get('source')} differs from {fmu}"
            bindings = c.findall("ssd:ParameterBindings/ssd:ParameterBinding", NS)
            assert len(bindings) == (1 if inst.get("parameters") else 0)
            if not bindings:
                continue
            source = bindings[0].get("source")
            ssv = etree.fromstring(z.read(source))
            assert ssv_schema.validate(ssv), f"{system}: {source}: {ssv_schema.error_log}"
            values = {}
            for p in ssv.findall("ssv:Parameters/ssv:Parameter", NS):
                (v,) = list(p)
                values[p.get("name")] = typed(etree.QName(v).localname, v.get("value"))
            assert values == {k: expected_value(v) for k, v in inst["parameters"].items()}, (system, inst["name"])
    step = ssd.find("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation/"
                    "{http://opensimulationplatform.com/SSP/OSPAnnotations}Algorithm/"
                    "{http://opensimulationplatform.com/SSP/OSPAnnotations}FixedStepAlgorithm", NS)
    assert float(step.get("baseStepSize")) == spec["simulation"]["step_size"]


def typed(element, text):
    """An SSV value as (element, value): a Real as its repr (the same text for the same bits)."""
    return (element, repr(float(text)) if element == "Real" else text)


def expected_value(v):
    """A system file value as the SSV element and text it should be written as (the current systems
    give numbers and booleans only; a TOML integer on a Real variable would read as Integer here
    and fail the comparison, which would then need the FMU's type)."""
    if isinstance(v, bool):
        return ("Boolean", "true" if v else "false")
    if isinstance(v, int):
        return ("Integer", str(v))
    assert isinstance(v, float), v
    return ("Real", repr(v))


def real_columns_csv(header, rows, fmus, tmp_path):
    """The shipsim CSV reduced to its Real columns (libcosim_runner.py reads Real values only)."""
    real = [0] + [j for j, h in enumerate(header) if j and
                  variables_by_name(fmus[h.split(".", 1)[0]])[h.split(".", 1)[1]].type == "Real"]
    out = tmp_path / "shipsim_real.csv"
    with open(out, "w", newline="") as f:
        csv.writer(f).writerows([[header[j] for j in real]] + [[repr(r[j]) for j in real] for r in rows])
    return out


def libcosim_ssp_rows(ssp_file, header, n_steps):
    """test_master_interop.libcosim_rows for an .ssp: libcosim_runner.main run in a child process
    (this file as a script) with CosimExecution.from_ssp_file in place of from_osp_config_file."""
    r = subprocess.run([sys.executable, __file__, str(ssp_file), str(n_steps), *header[1:]],
                       capture_output=True, text=True)
    assert r.returncode == 0, f"libcosim run of {ssp_file} failed ({r.returncode}):\n{r.stderr}"
    import json
    return json.loads(r.stdout)


@pytest.mark.parametrize("system", exportable(), ids=ids)
def test_export_equals_shipsim_in_libcosim(system, tmp_path, monkeypatch):
    toml, spec = localise(system, tmp_path)
    out = tmp_path / "shipsim.csv"
    shipsim("run", toml, "-o", out, "-q")
    ssp = tmp_path / f"{ids(system)}.ssp"
    export(toml, ssp)
    header, rows = read_csv(out)
    sim = spec["simulation"]
    n = round((sim["stop_time"] - sim.get("start_time", 0.0)) / sim["step_size"])
    assert len(rows) == n + 1, f"{system}: expected every base step recorded"
    assert_moves(system, header, rows)
    fmus = {i["name"]: tmp_path / os.path.basename(i["fmu"]) for i in spec["instances"]}
    out = real_columns_csv(header, rows, fmus, tmp_path)
    monkeypatch.setattr(test_master_interop, "libcosim_rows", libcosim_ssp_rows)
    worst = assert_same_as_libcosim(ssp, out, tol=0.0)
    print(f"{system}: {n} steps, {len(header) - 1} columns, worst |shipsim - libcosim(ssp)| = {worst:.3e}")


@pytest.mark.parametrize("system", exportable(), ids=ids)
def test_export_equals_shipsim_from_ssp(system, tmp_path):
    """shipsim run of the .ssp (the SSP importer) records the TOML run's columns bit for bit."""
    toml, _ = localise(system, tmp_path)
    ours = tmp_path / "toml.csv"
    shipsim("run", toml, "-o", ours, "-q")
    ssp = tmp_path / f"{ids(system)}.ssp"
    export(toml, ssp)
    theirs = tmp_path / "ssp.csv"
    shipsim("run", ssp, "-o", theirs, "-q")
    h1, r1 = read_csv(ours)
    h2, r2 = read_csv(theirs)
    missing = [h for h in h1 if h not in h2]
    assert not missing, f"{system}: the .ssp run does not record {missing}"
    col = [h2.index(h) for h in h1]
    assert len(r1) == len(r2), f"{system}: {len(r1)} rows from the TOML, {len(r2)} from the .ssp"
    for a, b in zip(r1, r2):
        got = [b[j] for j in col]
        assert got == a, f"{system}, t = {a[0]}: {[(h, x, y) for h, x, y in zip(h1, a, got) if x != y][:5]}"


MAPPED_SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations" name="mapped" version="1.0">
  <ssd:System name="mapped">
    <ssd:Elements>
      <ssd:Component name="A" source="Feedthrough.fmu">
        <ssd:Connectors>
          <ssd:Connector name="integer_output" kind="output"><ssc:Integer/></ssd:Connector>
          <ssd:Connector name="boolean_output" kind="output"><ssc:Boolean/></ssd:Connector>
          <ssd:Connector name="real_continuous_output" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="A">
                <ssv:Parameters>
                  <ssv:Parameter name="integer_input"><ssv:Integer value="2"/></ssv:Parameter>
                  <ssv:Parameter name="boolean_input"><ssv:Boolean value="true"/></ssv:Parameter>
                  <ssv:Parameter name="real_continuous_input"><ssv:Real value="1.5"/></ssv:Parameter>
                  <ssv:Parameter name="string_parameter"><ssv:String value="a &lt;b&gt; &amp; &quot;c&quot;"/></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="B" source="Feedthrough.fmu">
        <ssd:Connectors>
          <ssd:Connector name="integer_input" kind="input"><ssc:Integer/></ssd:Connector>
          <ssd:Connector name="boolean_input" kind="input"><ssc:Boolean/></ssd:Connector>
          <ssd:Connector name="real_continuous_input" kind="input"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="A" startConnector="integer_output" endElement="B" endConnector="integer_input">
        <ssc:IntegerMappingTransformation>
          <ssc:MapEntry source="1" target="100"/>
          <ssc:MapEntry source="2" target="200"/>
        </ssc:IntegerMappingTransformation>
      </ssd:Connection>
      <ssd:Connection startElement="A" startConnector="boolean_output" endElement="B" endConnector="boolean_input">
        <ssc:BooleanMappingTransformation>
          <ssc:MapEntry source="true" target="false"/>
          <ssc:MapEntry source="false" target="true"/>
        </ssc:BooleanMappingTransformation>
      </ssd:Connection>
      <ssd:Connection startElement="A" startConnector="real_continuous_output" endElement="B" endConnector="real_continuous_input">
        <ssc:LinearTransformation factor="2" offset="0.5"/>
      </ssd:Connection>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="1">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="0.25"/></osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


def test_mappings_and_strings_round_trip(tmp_path):
    """An SSD written here from SSP 1.0 (Integer and Boolean mapping transformations, a linear
    transformation, an inline parameter set with a String that needs XML escaping), run by shipsim,
    exported and run again from the .ssp: the same results, bit for bit, and the values the SSD
    defines, row by row (integer 1 -> 100 and 2 -> 200, boolean negated, 2 * 1.5 + 0.5 = 3.5, the
    String's length 11)."""
    import fixtures
    fixtures.build("Feedthrough", tmp_path)
    ssd = tmp_path / "SystemStructure.ssd"
    ssd.write_text(MAPPED_SSD)
    before = tmp_path / "ssd.csv"
    shipsim("run", ssd, "-o", before, "-q")
    ssp = tmp_path / "out" / "mapped.ssp"
    r = export(ssd, ssp)
    assert "libcosim applies no mapping transformation" in r.stderr, r.stderr
    with zipfile.ZipFile(ssp) as z:
        text = z.read("SystemStructure.ssd").decode()
        ssv = z.read("resources/A.ssv")
    schema = etree.XMLSchema(file=str(SCHEMA_DIR / "SystemStructureDescription.xsd"))
    assert schema.validate(etree.fromstring(text.encode())), schema.error_log
    schema = etree.XMLSchema(file=str(SCHEMA_DIR / "SystemStructureParameterValues.xsd"))
    assert schema.validate(etree.fromstring(ssv)), schema.error_log
    for entry in ['<ssc:MapEntry source="1" target="100"/>', '<ssc:MapEntry source="2" target="200"/>',
                  '<ssc:MapEntry source="false" target="true"/>', '<ssc:MapEntry source="true" target="false"/>',
                  '<ssc:LinearTransformation factor="2.0" offset="0.5"/>']:
        assert entry in text, entry
    after = tmp_path / "ssp.csv"
    shipsim("run", ssp, "-o", after, "-q")
    assert read_csv(after) == read_csv(before)
    header, rows = read_csv(after)
    col = {h: j for j, h in enumerate(header)}
    # Feedthrough adds its step count k to integer_output and flips boolean_output on odd k; B's
    # inputs at row k come from A's outputs at row k - 1 (row 0: after initialization).
    imap, bmap = {1: 100, 2: 200}, {1: 0, 0: 1}
    for k, r in enumerate(rows):
        src = rows[max(k - 1, 0)]
        a_int, a_bool = int(src[col["A.integer_output"]]), int(src[col["A.boolean_output"]])
        assert r[col["B.integer_output"]] == imap.get(a_int, a_int) + k, (k, r)
        assert r[col["B.boolean_output"]] == bmap[a_bool] ^ (k & 1), (k, r)
        assert r[col["B.real_continuous_output"]] == 2 * 1.5 + 0.5, (k, r)
        assert r[col["A.string_length"]] == len('a <b> & "c"'), (k, r)
    assert rows[0][col["B.integer_output"]] == 200 and len(rows) == 5


def fmpy_parameter_set(ssp):
    """The components' parameter sets of the archive, read with FMPy's read_ssv, as the one
    parameter set simulate_ssp takes (names prefixed with the component name, as it expects)."""
    from fmpy.ssp.ssd import ParameterSet, read_ssd
    ssd = read_ssd(str(ssp))
    merged = ParameterSet(name="shipsim")
    for c in ssd.system.elements:
        for b in c.parameterBindings:
            for ps in b.parameterValues:
                for p in ps.parameters:
                    p.name = f"{c.name}.{p.name}"
                    if p.type == "Boolean":
                        # read_ssv keeps the text; simulate_ssp sets a Boolean to `value != 0.0`,
                        # true for the text "false" too
                        p.value = {"true": True, "false": False}[p.value]
                    merged.parameters.append(p)
    return merged


@pytest.mark.parametrize("system", exportable(), ids=ids)
def test_fmpy_reads_export(system, tmp_path):
    """FMPy's read_ssd (which validates with the same schemas) reads the components, FMU sources,
    connections and each component's parameter set as the system file says; it finds no
    LinearTransformation on any connection (it looks in the wrong namespace), also where the SSD
    has one."""
    from fmpy.ssp.ssd import read_ssd
    toml, spec = localise(system, tmp_path)
    ssp = tmp_path / "out.ssp"
    export(toml, ssp)
    ssd = read_ssd(str(ssp))
    comps = {c.name: c for c in ssd.system.elements}
    assert list(comps) == [i["name"] for i in spec["instances"]]
    for inst in spec["instances"]:
        c = comps[inst["name"]]
        assert c.source.startswith("resources/") and c.source.endswith(".fmu")
        params = {p.name: typed(p.type, p.value)
                  for b in c.parameterBindings for ps in b.parameterValues for p in ps.parameters}
        assert params == {k: expected_value(v) for k, v in inst.get("parameters", {}).items()}
    got = [(f"{c.startElement}.{c.startConnector}", f"{c.endElement}.{c.endConnector}")
           for c in ssd.system.connections]
    written = toml_connections(spec)
    assert got == [(f, t) for f, t, _, _ in written]
    with zipfile.ZipFile(ssp) as z:
        in_ssd = z.read("SystemStructure.ssd").count(b"<ssc:LinearTransformation ")
    assert in_ssd == sum(1 for _, _, g, o in written if (g, o) != (1.0, 0.0))
    assert not any(hasattr(c, "linearTransformation") for c in ssd.system.connections)


def test_fmpy_simulates_export_within_its_subset(tmp_path):
    """FMPy's simulate_ssp runs the export of FMPY_SYSTEM (no gains, no step multiples) with the
    archive's parameters passed as its argument: every connection is applied at every step, and
    the recorded outputs are within REL_TOL of shipsim's."""
    from fmpy.ssp.simulation import simulate_ssp
    toml, spec = localise(FMPY_SYSTEM, tmp_path)
    assert all((g, o) == (1.0, 0.0) for _, _, g, o in toml_connections(spec))
    assert all(i.get("step_multiple", 1) == 1 for i in spec["instances"])
    h = spec["simulation"]["step_size"]
    out = tmp_path / "shipsim.csv"
    shipsim("run", toml, "-o", out, "-q", "--stop-time", repr(FMPY_STEPS * h))
    header, rows = read_csv(out)
    ssp = tmp_path / "out.ssp"
    export(toml, ssp)
    result = simulate_ssp(str(ssp), stop_time=FMPY_STEPS * h - h / 2, step_size=h,
                          parameter_set=fmpy_parameter_set(ssp))
    assert len(result) == FMPY_STEPS
    for f, t, _, _ in toml_connections(spec):
        assert (result[f] == result[t]).all(), f"FMPy did not apply {f} -> {t}"
    compared = [name for name in header[1:] if name in result.dtype.names]
    assert compared, "no recorded column is a connector"
    worst = 0.0
    for k in range(FMPY_STEPS):
        for name in compared:
            x, y = rows[k + 1][header.index(name)], float(result[name][k])
            worst = max(worst, abs(x - y) / max(1.0, abs(x)))
            assert abs(x - y) <= REL_TOL * max(1.0, abs(x)), f"step {k + 1}, {name}: shipsim {x!r}, FMPy {y!r}"
    print(f"{FMPY_SYSTEM}: {FMPY_STEPS} steps, {len(compared)} columns, worst relative |shipsim - FMPy| = {worst:.3e}")


def _libcosim_runner_from_ssp():
    """Child process: python test_ssp_export.py SSP_FILE N_STEPS COLUMN...; libcosim_runner.py run
    as the main script (same arguments) with the execution created from the .ssp."""
    import runpy
    from libcosimpy.CosimExecution import CosimExecution

    CosimExecution.from_osp_config_file = staticmethod(lambda path: CosimExecution.from_ssp_file(path))
    runpy.run_path(str(pathlib.Path(__file__).with_name("libcosim_runner.py")), run_name="__main__")


if __name__ == "__main__":
    _libcosim_runner_from_ssp()
