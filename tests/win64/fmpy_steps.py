"""Steps an FMU with fmpy and prints its outputs: run by the embeddable Windows Python under wine
(tests/test_win64.py) and by this machine's Python for the reference.

    python fmpy_steps.py FMU STEPS INPUT_NAMES OUTPUT_NAMES

INPUT_NAMES and OUTPUT_NAMES are comma-separated; the inputs before step k are those of the C host
(tests/c_host/host.c, set_inputs), assigned to the names in order (a name given twice takes the later
value, as in the C host). Prints "step <k> <outputs, repr>" lines, then "done".
"""
import shutil
import sys

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

H = 0.01


def host_inputs(k):
    return [8e3, -3e3, 3e4 + 1e3 * k, 1.5e3, -2.5e3, 0.4 + 0.01 * k, 0.05]


def main(fmu, steps, inputs, outputs):
    md = read_model_description(fmu)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    identifier = md.coSimulation.modelIdentifier
    folder = extract(fmu)
    version3 = md.fmiVersion.startswith("3")
    try:
        if version3:
            slave = FMU3Slave(guid=md.instantiationToken, unzipDirectory=folder, modelIdentifier=identifier,
                              instanceName="fmpy")
            slave.instantiate()
        else:
            slave = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=identifier, instanceName="fmpy")
            slave.instantiate()
            slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        set_values = slave.setFloat64 if version3 else slave.setReal
        get_values = slave.getFloat64 if version3 else slave.getReal
        for k in range(steps):
            for name, value in zip(inputs, host_inputs(k)):
                set_values([refs[name]], [value])
            slave.doStep(k * H, H)
            print("step", k, *(repr(float(v)) for v in get_values([refs[n] for n in outputs])), flush=True)
        slave.terminate()
        slave.freeInstance()
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    print("done", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), sys.argv[3].split(","), sys.argv[4].split(","))
