"""What our C host (tests/c_host/host.c) prints, read back: outputs per label and step, the
statuses of refused steps, the FMU's log lines and the error lines."""


def parse_host_output(stdout: str):
    """(values {label: {step: [outputs]}}, statuses [(label, step, status, terminated, last time)],
    logs [(status, category, message)], errors [lines])."""
    values, statuses, logs, errors = {}, [], [], []
    for line in stdout.splitlines():
        word, _, rest = line.partition(" ")
        if word == "status":
            label, k, status, terminated, last = rest.split()
            statuses.append((label, int(k), int(status), int(terminated), float(last)))
        elif word == "log":
            status, category, message = rest.split(" ", 2)
            logs.append((int(status), category, message))
        elif word == "error":
            errors.append(line)
        elif word != "done":
            k, *numbers = rest.split()
            values.setdefault(word, {})[int(k)] = [float(x) for x in numbers]
    return values, statuses, logs, errors
