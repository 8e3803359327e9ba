"""Executes examples/tour.ipynb headless against the test server: every cell
runs and its asserts hold (the notebook a new user opens first)."""
import os
import pathlib

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOK = pathlib.Path(__file__).resolve().parents[1] / "examples" / "tour.ipynb"


def test_the_tour_notebook_runs_top_to_bottom(server_address, monkeypatch):
    monkeypatch.setenv("KINPLAN_ADDRESS", server_address)
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    client.execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    # the last displayed value is the exploration summary
    shown = [o for o in outputs if o.get("output_type") == "execute_result"]
    assert "ExploreSummary" in shown[-1]["data"]["text/plain"]


VIZ_NOTEBOOK = NOTEBOOK.parent / "viz_tour.ipynb"


def test_the_viz_notebook_writes_a_recording(server_address, monkeypatch):
    pytest.importorskip("rerun")
    monkeypatch.setenv("KINPLAN_ADDRESS", server_address)
    nb = nbformat.read(VIZ_NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(VIZ_NOTEBOOK.parent)}})
    client.execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    shown = [o for o in outputs if o.get("output_type") == "execute_result"]
    assert "viz_tour.rrd" in shown[-1]["data"]["text/plain"]
