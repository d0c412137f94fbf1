"""The module's public names and its type stubs agree."""

import ast
from pathlib import Path

import smc_lmb


def test_stubs_name_exactly_the_public_functions_and_classes():
    stub = ast.parse((Path(__file__).resolve().parents[1] / "smc_lmb.pyi").read_text())
    stubbed = {n.name for n in stub.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    public = {n for n in dir(smc_lmb) if not n.startswith("_") and callable(getattr(smc_lmb, n))}
    public.discard("smc_lmb")  # the extension inside the package
    assert stubbed == public, (stubbed ^ public)
