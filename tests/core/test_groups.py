"""``make test GROUP=k/N`` (issue 25): pytest-split's groups of the regression, for N machines.

For N = 1..4 the groups are collected as ``make test GROUP=k/N`` runs them: disjoint, and together exactly
``make test``'s tests (the othersims ones left out before the split); a bad GROUP is refused with the reason.
"""

import subprocess
import sys

import pytest

from eyestereo.sim.measure import test_groups as G


def test_groups_of_one_to_four_machines_cover_make_test_exactly():
    whole = G.collect()
    others = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", "-m",
                             "othersims"], cwd=G.ROOT, capture_output=True, text=True).stdout
    others = {line.strip() for line in others.splitlines() if "::" in line}
    assert len(whole) > 3000 and len(others) > 20 and not others & set(whole)  # make test leaves them out
    for n in range(1, 5):
        r = G.check_groups(n, whole)  # raises when a test is in two groups or in none
        assert sum(r["tests"]) == len(whole) and len(r["tests"]) == n and min(r["tests"]) > 0


@pytest.mark.parametrize("bad,why", [("3", "want k/N"), ("0/4", "k must be 1..4"), ("5/4", "k must be 1..4"),
                                     ("1/0", "N must be"), ("a/b", "want k/N")])
def test_a_bad_group_is_refused_with_the_reason(bad, why):
    r = subprocess.run([sys.executable, "-m", "eyestereo.sim.measure.test_groups", "--check", bad],
                       capture_output=True, text=True)
    assert r.returncode == 2 and why in r.stderr and r.stderr.count("\n") == 1


def test_a_good_group_passes_the_check():
    assert G.parse_group("2/4") == (2, 4) and G.parse_group(" 1 / 1 ") == (1, 1)
    assert G.split_args(2, 4)[:4] == ["--splits", "4", "--group", "2"]
