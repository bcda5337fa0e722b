# SPDX-License-Identifier: Apache-2.0
"""viscera for Python: drive a session, read recordings into numpy and pandas, run the lab.

Submodules:

- ``viscera.session``: a client of a running viscera-server over DDS (claim an instrument, stream
  tool poses, receive forces, surface frames and events, session control).
- ``viscera.recording``: a session recording (MCAP) as pandas DataFrames and numpy arrays.
- ``viscera.lab``: viscera-lab's data sets, analysis and prediction.
- ``viscera.tissue``: the tissue core (mesh, material, GPS force model, integrators).

Units are SI and named in every field and column: metres, seconds, newtons, pascals, kilograms.
Errors are exceptions whose message is the one line the programs print: ``InputError`` (a file,
field or value that is wrong), ``UsageError`` (an argument), ``SimulationError`` (the physics went
unstable). Reference: docs/PYTHON.md.
"""

from ._viscera import InputError, SimulationError, UsageError
from . import lab, recording, session, tissue

__all__ = ["InputError", "UsageError", "SimulationError", "lab", "recording", "session", "tissue"]
