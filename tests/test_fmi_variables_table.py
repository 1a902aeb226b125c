"""resources/fmi_variables.tsv: the table of model variables build_fmu.py writes into every FMU
(fmu_build.shim.variables_table) and the FMI layer reads (fmu_src/shim/shim_rules.h).

Fast: no FMU is built. The C part compiles a small program against shim_rules.h (skipped without a
C compiler) and checks that it reads the table Python wrote, from the resource locations hosts give."""
from __future__ import annotations

import shutil
import subprocess
import urllib.parse
from pathlib import Path

import pytest

from fmu_build.shim import SHIM_DIR, VARIABLES_FILE, variables_table

FMI2 = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="SlewingBearing" guid="{abc}">
  <CoSimulation modelIdentifier="SlewingBearing"/>
  <ModelVariables>
    <ScalarVariable name="Fz" valueReference="2" causality="input" variability="continuous"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="preload" valueReference="7" causality="parameter" variability="fixed" initial="exact"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="ring_model" valueReference="12" causality="parameter" variability="fixed" initial="exact"><Integer start="1"/></ScalarVariable>
    <ScalarVariable name="max_ball_load" valueReference="24" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="flag" valueReference="30"><Boolean/></ScalarVariable>
  </ModelVariables>
  <ModelStructure/>
</fmiModelDescription>
"""

FMI3 = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="SlewingBearing" instantiationToken="{abc}">
  <CoSimulation modelIdentifier="SlewingBearing"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float64 name="Fz" valueReference="3" causality="input" start="0"/>
    <Int32 name="ring_model" valueReference="12" causality="parameter" variability="fixed" start="1"/>
    <Float64 name="ball_load" valueReference="40" causality="output"><Dimension start="8"/></Float64>
    <Float64 name="contact_angle" valueReference="41" causality="output"><Dimension start="8"/><Dimension start="4"/></Float64>
    <UInt64 name="n" valueReference="50" causality="structuralParameter" variability="fixed" start="3"/>
    <Float64 name="sized" valueReference="51" causality="output"><Dimension valueReference="50"/></Float64>
  </ModelVariables>
  <ModelStructure/>
</fmiModelDescription>
"""


def rows(table: str) -> list[list[str]]:
    return [line.split("\t") for line in table.splitlines() if line and not line.startswith("#")]


def test_fmi2_table_has_one_line_per_variable_with_the_standard_defaults():
    table = variables_table(FMI2.encode())
    assert rows(table) == [
        ["2", "Real", "input", "continuous", "", "Fz", "1"],
        ["7", "Real", "parameter", "fixed", "exact", "preload", "1"],
        ["12", "Integer", "parameter", "fixed", "exact", "ring_model", "1"],
        ["24", "Real", "output", "continuous", "", "max_ball_load", "1"],
        ["30", "Boolean", "local", "discrete", "", "flag", "1"],
    ]
    assert table.endswith("\n") and "\r" not in table


def test_fmi3_table_names_the_type_element_and_the_number_of_values():
    # n_values: the product of the Dimension starts; 0 where a structural parameter sizes the array
    assert rows(variables_table(FMI3)) == [
        ["0", "Float64", "independent", "continuous", "", "time", "1"],
        ["3", "Float64", "input", "continuous", "", "Fz", "1"],
        ["12", "Int32", "parameter", "fixed", "", "ring_model", "1"],
        ["40", "Float64", "output", "continuous", "", "ball_load", "8"],
        ["41", "Float64", "output", "continuous", "", "contact_angle", "32"],
        ["50", "UInt64", "structuralParameter", "fixed", "", "n", "1"],
        ["51", "Float64", "output", "continuous", "", "sized", "0"],
    ]


@pytest.mark.parametrize("broken, message", [
    (FMI2.replace('valueReference="7"', 'valueReference="x"'), "valueReference"),
    (FMI2.replace('<Integer start="1"/>', ""), "no type element"),
    (FMI2.replace("ModelVariables", "Variables"), "no ModelVariables"),
    (FMI3.replace('<Dimension start="8"/></Float64>', '<Dimension start="x"/></Float64>'), "Dimension"),
])
def test_a_description_the_table_cannot_hold_is_refused(broken, message):
    with pytest.raises(ValueError, match=message):
        variables_table(broken)


READER = r"""
#include "shim_platform.h"
#include "shim_rules.h"
int main(int argc, char **argv)
{
    ShimVariables t;
    char err[4096];
    if (shim_variables_load(&t, argv[1], err, sizeof err) != 0) {
        printf("ERROR %s\n", err);
        return 1;
    }
    for (int i = 2; i + 1 < argc; i += 2) {
        const ShimVariable *v = shim_variable_find(&t, argv[i][0] == '-' ? NULL : argv[i], (unsigned)atoi(argv[i + 1]));
        char why[256] = "";
        int running = v ? shim_may_set(v, SHIM_RUNNING, "fmi2ExitInitializationMode", why, sizeof why) : 0;
        printf("%s %s\n", v ? v->name : "-", v ? (running ? "settable" : why) : "");
        if (v)
            printf("values %lu\n", (unsigned long)v->n_values);
    }
    shim_variables_free(&t);
    return 0;
}
"""


@pytest.fixture(scope="module")
def reader(tmp_path_factory):
    compiler = shutil.which("cc") or shutil.which("gcc")
    if not compiler:
        pytest.skip("no C compiler")
    folder = tmp_path_factory.mktemp("reader")
    (folder / "reader.c").write_text(READER)
    run = subprocess.run([compiler, "-Wall", "-Werror", "-I", str(SHIM_DIR), "-o", str(folder / "reader"),
                          str(folder / "reader.c")], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return folder / "reader"


@pytest.mark.parametrize("form", ["uri", "file:/", "localhost", "path"])
def test_the_layer_reads_the_table_from_the_locations_hosts_give(reader, tmp_path, form):
    resources = tmp_path / "an FMU%dir" / "resources"  # a space and a '%': percent-encoded in the URI
    resources.mkdir(parents=True)
    (resources / VARIABLES_FILE).write_text(variables_table(FMI2))
    uri = resources.as_uri()
    location = {"uri": uri, "file:/": "file:" + urllib.parse.quote(str(resources)),
                "localhost": uri.replace("file://", "file://localhost"), "path": str(resources) + "/"}[form]
    assert "%20" in uri
    run = subprocess.run([str(reader), location, "Real", "24", "Integer", "12", "Real", "12", "-", "2",
                          "Real", "999"], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout
    assert run.stdout.splitlines() == [
        "max_ball_load is an output: it cannot be set", "values 1",
        "ring_model is a fixed parameter: it can be set only before fmi2ExitInitializationMode", "values 1",
        "- ",
        "Fz settable", "values 1",
        "- ",
    ]


def test_the_layer_reads_the_number_of_values(reader, tmp_path):
    (tmp_path / VARIABLES_FILE).write_text(variables_table(FMI3))
    run = subprocess.run([str(reader), str(tmp_path), "-", "40", "-", "41", "-", "51", "-", "3"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout
    assert run.stdout.splitlines()[1::2] == ["values 8", "values 32", "values 0", "values 1"]


def test_a_table_of_six_columns_is_read_with_the_number_of_values_unknown(reader, tmp_path):
    six = "".join("\t".join(line.split("\t")[:6]) + "\n" for line in variables_table(FMI3).splitlines())
    (tmp_path / VARIABLES_FILE).write_text(six)
    run = subprocess.run([str(reader), str(tmp_path), "-", "40"], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout
    assert run.stdout.splitlines() == ["ball_load is an output: it cannot be set", "values 0"]


def test_a_bad_number_of_values_is_named(reader, tmp_path):
    (tmp_path / VARIABLES_FILE).write_text(variables_table(FMI3).replace("ball_load\t8", "ball_load\tx"))
    run = subprocess.run([str(reader), str(tmp_path)], capture_output=True, text=True)
    assert run.returncode == 1
    assert "line 6: not value_reference" in run.stdout and "<TAB>n_values" in run.stdout


def test_a_missing_table_is_named(reader, tmp_path):
    run = subprocess.run([str(reader), tmp_path.as_uri()], capture_output=True, text=True)
    assert run.returncode == 1
    assert f"{tmp_path}/{VARIABLES_FILE} is missing" in run.stdout
