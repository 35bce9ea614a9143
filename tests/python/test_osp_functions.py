"""OSP functions, variable groups and summed inputs (issue 17): one OspSystemStructure.xml run by
libcosim and by shipsim gives the same numbers, bit for bit (tolerance 0).

The file holds, over the Feedthrough fixture (tests/fixtures/fmus/Feedthrough; each output is
its input plus real_tunable_parameter * time, so a sink with parameter 0 shows its input):
* a Sum of four inputs into one input (libcosim adds in[0], in[1], ... in index order; the
  sources' values are chosen so that another order gives other bits, which the test checks);
* a LinearTransformation;
* a VectorSum of three variable groups of dimension 2;
* a VariableGroupConnection of two LinearMechanicalPorts (Force and LinearVelocity groups),
  the groups declared in Feedthrough_OspModelDescription.xml beside the FMU (OSP-IS).

A native TOML with `sum = true` on three connections is exported (`shipsim export-osp`, a Sum
function) and equals libcosim's run of the export; a double connection without `sum = true` is
still refused by `shipsim check`.

Environment: SHIPSIM_BIN (the master).
"""
import textwrap

import pytest

import fixtures
from test_master_interop import libcosim_rows, read_csv, shipsim

H = 0.0625
STOP = 2.0

# Sources: (real_continuous_input, real_discrete_input, real_tunable_parameter).
SOURCES = {
    "a": (0.1, 1e-3, 0.7),
    "b": (0.2, 2.5, -0.3),
    "c": (0.3, -1.75, 1.1),
    "d": (1e-17, 5.0, 1e-3),
}

GROUPS = """<?xml version="1.0" encoding="utf-8"?>
<OspModelDescription xmlns="https://opensimulationplatform.com/xsd/OspModelDescription-1.0.0" version="1.0">
  <VariableGroups>
    <Generic name="vec_in">
      <Variable ref="real_continuous_input"/>
      <Variable ref="real_discrete_input"/>
    </Generic>
    <Generic name="vec_out">
      <Variable ref="real_continuous_output"/>
      <Variable ref="real_discrete_output"/>
    </Generic>
    <LinearMechanicalPort name="port_out">
      <Force name="force_out"><Variable ref="real_continuous_output"/></Force>
      <LinearVelocity name="velocity_in"><Variable ref="real_discrete_input"/></LinearVelocity>
    </LinearMechanicalPort>
    <LinearMechanicalPort name="port_in">
      <Force name="force_in"><Variable ref="real_continuous_input"/></Force>
      <LinearVelocity name="velocity_out"><Variable ref="real_discrete_output"/></LinearVelocity>
    </LinearMechanicalPort>
  </VariableGroups>
</OspModelDescription>
"""

SUM_ORDER = ["c", "a", "b", "d"]
VECTOR_SUM_ORDER = ["b", "c", "a"]


def simulator(name, values, multiple=1):
    inits = "".join(f'<InitialValue variable="{k}"><Real value="{v!r}"/></InitialValue>' for k, v in values.items())
    return (f'<Simulator name="{name}" source="Feedthrough.fmu" stepSize="{multiple * H!r}">'
            f'<InitialValues>{inits}</InitialValues></Simulator>')


def signal(sim, var, function, name):
    return (f'<SignalConnection><Variable simulator="{sim}" name="{var}"/>'
            f'<Signal function="{function}" name="{name}"/></SignalConnection>')


def signal_group(sim, group, function, name):
    return (f'<SignalGroupConnection><SignalGroup function="{function}" name="{name}"/>'
            f'<VariableGroup simulator="{sim}" name="{group}"/></SignalGroupConnection>')


def osp_file(rates):
    """`rates`: step multiples of simulators (1 for the others)."""
    sims = [simulator(n, {"real_continuous_input": ci, "real_discrete_input": di, "real_tunable_parameter": p},
                      rates.get(n, 1))
            for n, (ci, di, p) in SOURCES.items()]
    sims += [simulator(n, {"real_tunable_parameter": 0.0}, rates.get(n, 1)) for n in ["s1", "s2", "s3", "s4"]]
    # z's output is -0.0 + (-0.0)*t = -0.0, passed to s5 (whose -0.0*t keeps the sign of zero)
    sims += [simulator("z", {"real_continuous_input": -0.0, "real_tunable_parameter": -0.0}),
             simulator("s5", {"real_tunable_parameter": -0.0})]
    conns = [signal(s, "real_continuous_output", "total", f"in[{i}]") for i, s in enumerate(SUM_ORDER)]
    conns.append(signal("s1", "real_continuous_input", "total", "out"))
    conns += [signal("a", "real_continuous_output", "scale", "in"),
              signal("s2", "real_continuous_input", "scale", "out")]
    conns += [signal_group(s, "vec_out", "vsum", f"in[{i}]") for i, s in enumerate(VECTOR_SUM_ORDER)]
    conns.append(signal_group("s3", "vec_in", "vsum", "out"))
    conns.append('<VariableConnection><Variable simulator="z" name="real_continuous_output"/>'
                 '<Variable simulator="s5" name="real_continuous_input"/></VariableConnection>')
    conns.append('<VariableGroupConnection><VariableGroup simulator="d" name="port_out"/>'
                 '<VariableGroup simulator="s4" name="port_in"/></VariableGroupConnection>')
    nl = "\n        "
    return f"""<?xml version="1.0" encoding="utf-8"?>
<OspSystemStructure xmlns="http://opensimulationplatform.com/MSMI/OSPSystemStructure" version="0.1">
    <StartTime>0.0</StartTime>
    <EndTime>{STOP!r}</EndTime>
    <BaseStepSize>{H!r}</BaseStepSize>
    <Algorithm>fixedStep</Algorithm>
    <Simulators>
        {nl.join(sims)}
    </Simulators>
    <Functions>
        <LinearTransformation name="scale" factor="3.3" offset="-0.1"/>
        <Sum name="total" inputCount="{len(SUM_ORDER)}"/>
        <VectorSum name="vsum" inputCount="{len(VECTOR_SUM_ORDER)}" dimension="2"/>
    </Functions>
    <Connections>
        {nl.join(conns)}
    </Connections>
</OspSystemStructure>
"""


@pytest.fixture(scope="module")
def feedthrough(tmp_path_factory):
    d = tmp_path_factory.mktemp("feedthrough")
    return fixtures.build("Feedthrough", d)


def columns(header, rows, names):
    return {n: [r[header.index(n)] for r in rows] for n in names}


def bits_equal(x, y):
    return [float(a).hex() for a in x] == [float(b).hex() for b in y]


def left_fold(values):
    total = values[0]
    for v in values[1:]:
        total = total + v
    return total


# Single rate, and multi-rate: sources and a sum's target at 2 and 4 base steps.
RATES = [{}, {"b": 2, "c": 4, "s3": 2, "d": 2}]


@pytest.mark.parametrize("rates", RATES, ids=["single-rate", "multi-rate"])
def test_osp_functions_and_groups_equal_libcosim_bit_for_bit(feedthrough, tmp_path, rates):
    (tmp_path / "Feedthrough.fmu").write_bytes(feedthrough.read_bytes())
    (tmp_path / "Feedthrough_OspModelDescription.xml").write_text(GROUPS)
    osp = tmp_path / "OspSystemStructure.xml"
    osp.write_text(osp_file(rates))
    shipsim("run", osp, "-o", tmp_path / "ours.csv")
    header, ours = read_csv(tmp_path / "ours.csv")
    out = "real_continuous_output"
    dout = "real_discrete_output"
    wanted = ["time"] + [f"{s}.{out}" for s in ["a", "b", "c", "d", "s1", "s2", "s3", "s4", "z", "s5"]] \
        + [f"{s}.{dout}" for s in ["a", "b", "c", "d", "s3", "s4"]]
    assert all(w in header for w in wanted), header
    ours = [[r[header.index(w)] for w in wanted] for r in ours]
    theirs = libcosim_rows(osp, wanted, len(ours) - 1)
    assert len(theirs) == len(ours) - 1 == round(STOP / H)
    for k, (a, b) in enumerate(zip(ours[1:], theirs), start=1):
        for name, x, y in zip(wanted[1:], a[1:], b):
            assert float(x).hex() == float(y).hex(), f"row {k} (t = {a[0]}), {name}: shipsim {x!r} vs libcosim {y!r}"
    col = {w: [r[j] for r in ours] for j, w in enumerate(wanted)}
    # A plain connection passes -0.0 on as libcosim does (compared above; here: it is -0.0).
    assert {float(x).hex() for x in col[f"s5.{out}"]} == {"-0x0.0p+0"}
    assert len(set(col[f"s1.{out}"][1:])) > 10 and len(set(col[f"s3.{out}"][1:])) > 5, "sums do not move"
    if rates:
        return  # the checks below follow the single-rate timing (one step of delay)

    # The Sum: s1 shows, one step later, the left fold of the sources in index order ...
    src = [col[f"{s}.{out}"] for s in SUM_ORDER]
    expected = [left_fold([x[k - 1] for x in src]) for k in range(1, len(ours))]
    assert bits_equal(col[f"s1.{out}"][1:], expected)
    # ... which another order would not give: the order is what the test checks.
    for other in (list(reversed(src)), src[1:] + src[:1]):
        folded = [left_fold([x[k - 1] for x in other]) for k in range(1, len(ours))]
        assert not bits_equal(folded, expected)
    # The LinearTransformation: offset + factor * in.
    assert bits_equal(col[f"s2.{out}"][1:], [-0.1 + 3.3 * x for x in col[f"a.{out}"][:-1]])
    # The VectorSum, component by component, inputs in index order.
    for comp in (out, dout):
        src = [col[f"{s}.{comp}"] for s in VECTOR_SUM_ORDER]
        assert bits_equal(col[f"s3.{comp}"][1:], [left_fold([x[k - 1] for x in src]) for k in range(1, len(ours))])
    # The port: d's force drives s4's force input, s4's velocity output drives d's velocity input.
    assert bits_equal(col[f"s4.{out}"][1:], col[f"d.{out}"][:-1])
    # (s4's velocity output is its unconnected discrete input, 0.0: d's 5.0 is replaced by it)
    assert set(col[f"d.{dout}"]) == {0.0} and set(col[f"s4.{dout}"]) == {0.0}


TOML = """
connections = [
    "c.real_continuous_output -> s.real_continuous_input, sum",
    "a.real_continuous_output -> s.real_continuous_input, sum",
    "b.real_continuous_output -> s.real_continuous_input, sum",
    "d.real_continuous_output -> s.real_continuous_input, sum",
]
[simulation]
stop_time = {stop!r}
step_size = {h!r}
{instances}
[[instances]]
name = "s"
fmu = "Feedthrough.fmu"
"""


def toml_instances():
    return "".join(textwrap.dedent(f"""
        [[instances]]
        name = "{n}"
        fmu = "Feedthrough.fmu"
        parameters = {{ real_continuous_input = {ci!r}, real_tunable_parameter = {p!r} }}
    """) for n, (ci, _, p) in SOURCES.items())


def test_toml_sum_exported_as_osp_sum_equals_libcosim(feedthrough, tmp_path):
    (tmp_path / "Feedthrough.fmu").write_bytes(feedthrough.read_bytes())
    (tmp_path / "sum.toml").write_text(TOML.format(stop=STOP, h=H, instances=toml_instances()))
    shipsim("run", tmp_path / "sum.toml", "-o", tmp_path / "sum.csv")
    shipsim("export-osp", tmp_path / "sum.toml", "-o", tmp_path / "OspSystemStructure.xml")
    xml = (tmp_path / "OspSystemStructure.xml").read_text()
    assert '<Sum name="sum0" inputCount="4"/>' in xml
    header, ours = read_csv(tmp_path / "sum.csv")
    wanted = ["time", "s.real_continuous_output", "a.real_continuous_output"]
    ours = [[r[header.index(w)] for w in wanted] for r in ours]
    theirs = libcosim_rows(tmp_path / "OspSystemStructure.xml", wanted, len(ours) - 1)
    assert [[float(x).hex() for x in r[1:]] for r in ours[1:]] == [[float(x).hex() for x in r] for r in theirs]
    assert len(set(r[1] for r in ours)) > 10


def test_double_connection_without_sum_is_refused(feedthrough, tmp_path):
    (tmp_path / "Feedthrough.fmu").write_bytes(feedthrough.read_bytes())
    text = TOML.format(stop=STOP, h=H, instances=toml_instances()).replace(", sum\"", "\"")
    (tmp_path / "twice.toml").write_text(text)
    r = shipsim("check", tmp_path / "twice.toml", check=False)
    assert r.returncode != 0
    assert "twice.toml:4: input 's.real_continuous_input' is driven twice: by a.real_continuous_output -> " \
           "s.real_continuous_input and by c.real_continuous_output -> s.real_continuous_input (line 3); " \
           "to add them, set sum = true on every connection into it" in r.stderr, r.stderr
