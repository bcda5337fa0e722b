# SPDX-License-Identifier: Apache-2.0
"""The tissue core: an organ mesh with a material, a force model and an integrator.

``Organ(mesh, material=..., fixed_nodes=...)`` builds it as viscera-sim does; ``advance(seconds)``
steps it with the interpreter lock released; ``positions`` and ``velocities`` are read-only
(nodes, 3) numpy views of the state, valid while the organ lives; ``edge_strains()`` gives each
tetrahedron's six edge strains (L - L0) / L0, the quantities the GPS's tensions depend on.
"""

from ._viscera.tissue import Organ, force_model_names

__all__ = ["Organ", "force_model_names"]
