"""``ContactPairs`` — the pairs of bodies in contact, read once from the plant's contact results.

The station's ``CollisionProbe`` reads its output.  Reading a ``ContactResults`` from Python costs
a binding call per contact and per field (about 3 µs a contact on Drake 1.51's bindings, a part
resting on a belt alone making 5 point contacts), so it is read here once per contact result.
(A pick run records ``probe.PickProbe`` instead: it keeps each sample's contact results and
reads them after the run, for its flags, pad forces and the same collision flags.)

Its output ``contact_pairs`` is a tuple with one ``(body A, body B, where)`` per contact, in the
order of the contact results: the point pairs first (``where`` = i ≥ 0, the point pair's index),
then the hydroelastic contacts (``where`` = −1 − j for hydroelastic contact j; bodies through
the model's geometry-to-body map).  ``where`` lets a reader fetch that contact's force from the
same ``ContactResults`` (``contact_force``).

==================  ======  ======================================================
port                type    meaning
==================  ======  ======================================================
``contact_results`` —       input: the plant's ContactResults
``contact_pairs``   tuple   output: ``(body A, body B, where)`` per contact
==================  ======  ======================================================
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.plant import ContactResults
from pydrake.systems.framework import LeafSystem


class ContactPairs(LeafSystem):
    """The bodies of every contact (module docstring); ``body_of_geometry``: GeometryId → body
    index (hydroelastic contacts report geometries)."""

    def __init__(self, body_of_geometry: dict):
        super().__init__()
        self._geometry = body_of_geometry
        self._contacts = self.DeclareAbstractInputPort("contact_results",
                                                       AbstractValue.Make(ContactResults()))
        self.DeclareAbstractOutputPort("contact_pairs", lambda: AbstractValue.Make(()), self._calc)

    def _calc(self, context, output) -> None:
        output.set_value(contact_pairs(self._contacts.Eval(context), self._geometry))


def contact_pairs(results: ContactResults, body_of_geometry: dict) -> tuple:
    """``(body A, body B, where)`` of every contact in ``results`` (module docstring)."""
    pairs = []
    info = results.point_pair_contact_info
    for i in range(results.num_point_pair_contacts()):
        c = info(i)
        pairs.append((int(c.bodyA_index()), int(c.bodyB_index()), i))
    for j in range(results.num_hydroelastic_contacts()):
        surface = results.hydroelastic_contact_info(j).contact_surface()
        pairs.append((body_of_geometry[surface.id_M()], body_of_geometry[surface.id_N()], -1 - j))
    return tuple(pairs)


def contact_force(results: ContactResults, where: int) -> np.ndarray:
    """The force of contact ``where`` (``contact_pairs``) on its body B, world frame (N): a
    point pair's ``contact_force``, or −(the force on a hydroelastic surface's M body)."""
    if where >= 0:
        return np.array(results.point_pair_contact_info(where).contact_force())
    return -np.array(results.hydroelastic_contact_info(-1 - where).F_Ac_W().translational())
