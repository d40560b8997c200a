"""Counting assertions shared by the output checks: each check is counted, failures printed,
and the exit code says whether any failed."""

counts = {"passed": 0, "failed": 0}


def check(name, ok, detail=""):
    if ok:
        counts["passed"] += 1
    else:
        counts["failed"] += 1
        print(f"FAILED {name} {detail}")


def report(what):
    """Prints the tally and returns the exit code."""
    print(f"{what}: {counts['passed']} checks passed, {counts['failed']} failed")
    return 1 if counts["failed"] else 0
