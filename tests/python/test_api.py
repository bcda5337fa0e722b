# SPDX-License-Identifier: Apache-2.0
"""The package's surface: every public name documented, the exceptions in their places."""

from __future__ import annotations

import inspect

import viscera


def test_every_public_name_has_a_docstring() -> None:
    missing = []
    for module_name in ("session", "recording", "lab", "tissue"):
        module = getattr(viscera, module_name)
        assert (module.__doc__ or "").strip(), module_name
        for name in module.__all__:
            obj = getattr(module, name)
            if not (obj.__doc__ or "").strip():
                missing.append(f"{module_name}.{name}")
            if inspect.isclass(obj):
                for attribute, value in vars(obj).items():
                    if attribute.startswith("_") or (obj is viscera.session.ServerState and attribute in ("name", "value")):
                        continue  # pybind11's own enum members
                    doc = (getattr(value, "__doc__", None) or "").strip()
                    if not doc or doc.startswith("(self"):  # pybind11's bare signature
                        missing.append(f"{module_name}.{name}.{attribute}")
    assert not missing, f"no docstring: {', '.join(missing)}"


def test_errors_are_the_built_in_kinds() -> None:
    assert issubclass(viscera.InputError, ValueError)
    assert issubclass(viscera.UsageError, ValueError)
    assert issubclass(viscera.SimulationError, RuntimeError)
