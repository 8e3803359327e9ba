"""The package's types catch mistakes before a call is made: mypy --strict
on small user programs (needs mypy, in the test extras)."""
import os
import pathlib
import textwrap

import pytest

api = pytest.importorskip("mypy.api")

PACKAGE = pathlib.Path(__file__).resolve().parents[1]


def check(tmp_path: pathlib.Path, source: str) -> str:
    path = tmp_path / "user.py"
    path.write_text(textwrap.dedent(source))
    # this checkout's package (also when it is installed editable, which mypy cannot follow)
    os.environ["MYPYPATH"] = str(PACKAGE)
    cache = tmp_path.parent.parent / "kinplan-mypy-cache"  # shared by the tests of a session
    out, err, status = api.run(["--strict", "--follow-imports=silent", "--cache-dir", str(cache),
                                "--config-file", os.devnull, str(path)])
    return out


def test_a_correct_program_type_checks(tmp_path):
    out = check(tmp_path, """
        import numpy as np
        import numpy.typing as npt
        import kinplan

        def tool(c: kinplan.Client) -> npt.NDArray[np.float64]:
            robot = c.robot("ur5")
            T = robot.fk(np.zeros(6))
            T2, links = robot.fk([0.0] * 6, links=True)
            answer = robot.ik(T, method="lm", linear_solver="svd", max_iterations=50)
            return T @ T2
    """)
    assert "Success" in out, out


def test_misspelt_options_and_unknown_method_names_are_type_errors(tmp_path):
    out = check(tmp_path, """
        import numpy as np
        import kinplan

        def solve(c: kinplan.Client) -> None:
            robot = c.robot("ur5")
            robot.ik(np.eye(4), methd="lm")
            robot.ik(np.eye(4), method="lmm")
    """)
    assert 'Unexpected keyword argument "methd"' in out, out
    assert "Literal['lmm']" in out, out
