"""Where pybullet does not do what its documentation says: the one list, with the evidence.

Every check encodes the *documented* behaviour. Where the installed pybullet is known to deviate,
the check carries ``expected_failure(id)``: a ``pytest.mark.xfail(strict=True)`` whose reason says
what the document says, what pybullet does and where that was shown. The mark is keyed by pybullet
version: it applies only when the installed pybullet is in the deviation's ``affected`` range, and
it is strict, so a pybullet in that range that behaves as documented turns the check into
``XPASS(strict)``, a failure: a deviation that goes away is reported, never passed in silence.
The ranges are open towards newer releases on purpose (every deviation here is still present on
bullet3's master branch, and the upstream issues are open); when a release fixes one, close its
range below that release.

``python -m conformance documented`` measures every documented statement the checks rely on, these
included, on the installed pybullet and prints the table (``conformance.checks.documented``).
"""

from __future__ import annotations

import importlib.metadata
from dataclasses import dataclass

import pytest
from hypothesis import Phase
from packaging.specifiers import SpecifierSet
from packaging.version import Version

__all__ = ["DEVIATIONS", "NO_SHRINK", "Deviation", "applies", "expected_failure", "get", "installed_pybullet"]

QUICKSTART = "PyBullet Quickstart Guide (Coumans & Bai, 2016–2022)"

#: Hypothesis phases for a check that carries ``expected_failure``: the first failing example
#: decides a strict xfail, so shrinking it would only cost time.
NO_SHRINK = (Phase.explicit, Phase.reuse, Phase.generate)


@dataclass(frozen=True)
class Deviation:
    """One documented statement that the installed pybullet does not keep.

    ``affected`` is a PEP 440 specifier of the pybullet versions that deviate; ``measured_on`` are
    the versions the kit's own measurement (``observed``) was made on.
    """

    id: str
    document: str
    quote: str
    documented: str
    observed: str
    evidence: tuple[str, ...]
    affected: str
    measured_on: tuple[str, ...]
    check: str  # the check that encodes the documented behaviour (module::function)

    def applies(self, version: str | None = None) -> bool:
        """Whether pybullet ``version`` (default: the installed one) is in the affected range."""
        return Version(version or installed_pybullet()) in SpecifierSet(self.affected)

    def reason(self) -> str:
        return (f"known pybullet deviation {self.id!r} (pybullet {self.affected}; measured on "
                f"{', '.join(self.measured_on)}): the {self.document} says \"{self.quote}\" — documented: "
                f"{self.documented}; observed: {self.observed}. Evidence: {'; '.join(self.evidence)}. "
                "If this check passes, pybullet now behaves as documented: narrow the range in "
                "conformance/bullet/deviations.py.")


DEVIATIONS: tuple[Deviation, ...] = (
    Deviation(
        id="default-collision-filter-mode",
        document=f"{QUICKSTART}, setPhysicsEngineParameter",
        quote="collisionFilterMode int Use 0 for default collision filter: (group A&maskB) AND (groupB&maskA). "
              "Use 1 to switch to the OR collision filter: (group A&maskB) OR (groupB&maskA)",
        documented="without setPhysicsEngineParameter(collisionFilterMode=…), a pair collides only if each "
                   "body's group is in the other's mask (AND)",
        observed="the default is the OR rule: a pair collides if either body's group is in the other's mask; "
                 "collisionFilterMode=0 must be set explicitly (after every resetSimulation) to get AND",
        evidence=(
            "bullet3 issue #4148 'Default collision group filter mode not AND as expected' (open)",
            "bullet3 examples/SharedMemory/PhysicsServerCommandProcessor.cpp, createEmptyDynamicsWorld: "
            "m_broadphaseCollisionFilterCallback->m_filterMode = B3_FILTER_GROUPAMASKB_OR_GROUPBMASKA",
            "measured with the crossing scene: groups/masks (1, 2, 2, 4) collide by default, pass with mode 0",
        ),
        affected=">=3.2.5",
        measured_on=("3.2.7",),
        check="conformance/test_filters.py::test_default_filter_mode_is_and",
    ),
    Deviation(
        id="maximal-coordinates-damping-default",
        document=f"{QUICKSTART}, changeDynamics",
        quote="linearDamping double linear damping of the link (0.04 by default)",
        documented="a body created with useMaximalCoordinates=True is damped as if linearDamping = "
                   "angularDamping = 0.04 had been set",
        observed="maximal-coordinate bodies start undamped (0): they keep their speed and spin exactly until "
                 "changeDynamics sets a damping (multibodies do default to 0.04)",
        evidence=(
            "bullet3 src/BulletDynamics/Dynamics/btRigidBody.h, btRigidBodyConstructionInfo: "
            "m_linearDamping(btScalar(0.)), m_angularDamping(btScalar(0.)) — while btMultiBody.cpp "
            "initialises m_linearDamping(0.04f), m_angularDamping(0.04f)",
            "measured: from 2 m/s and 3 rad/s a maximal-coordinate sphere keeps 2.0 and 3.0 after a step; with "
            "linearDamping=0.04 set it has 2·0.96^(1/240)",
        ),
        affected=">=3.2.5",
        measured_on=("3.2.7",),
        check="conformance/test_materials.py::test_maximal_coordinate_damping_defaults_to_004",
    ),
    Deviation(
        id="velocity-clamp-on-free-base",
        document=f"{QUICKSTART}, changeDynamics",
        quote="maxJointVelocity double maximum joint velocity for a given joint, if it is exceeded during "
              "constraint solving, it is clamped to avoid crashing the simulation. […] Default maximum joint "
              "velocity is 100 units.",
        documented="a free base with no joint, contact or constraint is not clamped: a push changes its "
                   "velocity by F·dt/m whatever the result",
        observed="every velocity coordinate of a multibody, the free base's three linear and three angular "
                 "ones included, is clamped to ±100 after every step: a 12 s free fall ends at −100 m/s, not "
                 "−120 m/s, and the guide's ball collision (40 kN for 1/240 s on 0.5 kg) flies at 100 m/s, not 333",
        evidence=(
            "bullet3 src/BulletDynamics/Featherstone/btMultiBody.h, applyDeltaVeeMultiDof: "
            "btClamp(m_realBuf[dof], -m_maxCoordinateVelocity, m_maxCoordinateVelocity) for every dof "
            "including the base's 6; btMultiBody.cpp: m_maxCoordinateVelocity(100.f)",
            "measured: a one-step push to 200 m/s gives exactly 100.0; with changeDynamics(maxJointVelocity=1000) "
            "it gives F·dt/m",
        ),
        affected=">=3.2.5",
        measured_on=("3.2.7",),
        check="conformance/test_forces.py::test_free_base_is_not_clamped",
    ),
)

_BY_ID = {d.id: d for d in DEVIATIONS}


def installed_pybullet() -> str:
    return importlib.metadata.version("pybullet")


def get(deviation_id: str) -> Deviation:
    try:
        return _BY_ID[deviation_id]
    except KeyError:
        raise KeyError(f"deviation={deviation_id!r}, but should be one of {', '.join(_BY_ID)}") from None


def applies(deviation_id: str, version: str | None = None) -> bool:
    return get(deviation_id).applies(version)


def expected_failure(deviation_id: str, version: str | None = None) -> pytest.MarkDecorator:
    """``xfail(strict=True)`` with the deviation's reason when it applies to ``version`` (default: the
    installed pybullet); otherwise the same mark with a false condition, so the check runs plainly."""
    deviation = get(deviation_id)
    return pytest.mark.xfail(deviation.applies(version), reason=deviation.reason(), strict=True)
