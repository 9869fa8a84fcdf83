"""The zoo's population: the model files pyBullet ships in ``pybullet_data``, and what each holds.

Every URDF outside ``random_urdfs/``, every SDF and every MJCF file, and a seeded sample of the 1,000
``random_urdfs/`` mesh objects. :func:`survey` loads each in a process of its own (pyBullet crashes
loading some: ``gripper/wsg50_one_motor_gripper_free_base.sdf`` ends its process with signal 11 in
pybullet 3.2.7), reads what a program would draw (``getVisualShapeData``; each mesh read with trimesh,
as the programs read it) and steps it as the programs do (on ``plane.urdf``, lifted to stand on it, joints
on position motors) to learn whether anything moves. A model that does not load, has nothing to draw, or
has nothing that moves cannot tell a right drawing from a wrong one: it is listed with the reason, not judged.
"""

from __future__ import annotations

import json
import os
import random
from dataclasses import asdict, dataclass, field
from pathlib import Path

__all__ = ["LIFT", "Model", "RANDOM_SAMPLE", "Survey", "data_path", "population", "survey"]

#: how many of ``random_urdfs/`` the population takes, unless told otherwise
RANDOM_SAMPLE = 20
#: the gap the programs leave between a model's lowest point and the ground when they lift it there (m)
LIFT = 0.02
#: steps of the survey's run (what moves in them is what the programs' first ticks show)
SURVEY_STEPS = 40
#: a model whose frames all move less than this over the survey's run has nothing that moves (m or rad)
STILL = 1e-4


def data_path() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath())


@dataclass(frozen=True)
class Model:
    """One model file of ``pybullet_data``: its path there, and the call that loads it."""

    path: str

    @property
    def loader(self) -> str:
        return {".sdf": "loadSDF", ".xml": "loadMJCF"}.get(Path(self.path).suffix, "loadURDF")

    @property
    def name(self) -> str:
        """The model's id in tables and pytest ids: its path without the suffix, ``/`` as ``.``."""
        return str(Path(self.path).with_suffix("")).replace("/", ".")


def population(random_sample: int = RANDOM_SAMPLE, seed: int = 0) -> list[Model]:
    """Every URDF (but ``random_urdfs/``), SDF and MJCF file of ``pybullet_data``, then ``random_sample`` of
    ``random_urdfs/``, drawn with ``seed``: sorted, the same list for the same pybullet_data and arguments."""
    root = data_path()
    found = []
    for pattern in ("*.urdf", "*.sdf", "*.xml"):
        found += [p.relative_to(root).as_posix() for p in root.rglob(pattern)]
    random_urdfs = sorted(p for p in found if p.startswith("random_urdfs/"))
    chosen = sorted(p for p in found if not p.startswith("random_urdfs/"))
    sample = random.Random(seed).sample(random_urdfs, min(random_sample, len(random_urdfs)))
    return [Model(p) for p in chosen + sorted(sample)]


@dataclass
class Survey:
    """What one model holds, as the programs will meet it; ``unusable`` says why it cannot be judged."""

    model: str
    unusable: str = ""
    bodies: int = 0
    links: int = 0
    movable: int = 0         # revolute and prismatic joints: what motors drive and playback resets
    fixed_joints: int = 0    # what URDF_MERGE_FIXED_LINKS merges
    spheres: int = 0         # sphere visual shapes (FURY 2's impostor spheres draw them)
    dynamic: bool = False    # some base or link has mass: useFixedBase changes something
    moved: float = 0.0       # the most any frame moved over the survey's run (m, or rad times 0.1 m)
    kinds: list = field(default_factory=list)  # the visual shapes' kinds

    def as_dict(self) -> dict:
        return asdict(self)


def survey(models: list[Model], *, timeout: float = 120.0) -> dict[str, Survey]:
    """:class:`Survey` of each model, each made in a process forked for it (a crash or hang costs that model only)."""
    return {model.path: _survey_forked(model, timeout) for model in models}


def _survey_forked(model: Model, timeout: float) -> Survey:
    import select
    import signal
    import time

    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: survey, write JSON, leave without running the parent's exit handlers
        os.close(read)
        try:
            import faulthandler

            faulthandler.disable()  # a crash loading the model is the survey's answer, not a dump in the caller's output
            os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
            os.dup2(os.open(os.devnull, os.O_WRONLY), 2)  # pyBullet's warnings
            text = json.dumps(_survey_here(model).as_dict()).encode()
        except BaseException as exc:  # noqa: BLE001 - the child reports every failure as the model's
            text = json.dumps(Survey(model.path, f"the survey raised {type(exc).__name__}: {exc}").as_dict()).encode()
        with os.fdopen(write, "wb") as out:
            out.write(text)
        os._exit(0)
    os.close(write)
    chunks, deadline = [], time.monotonic() + timeout
    with os.fdopen(read, "rb") as pipe:
        while True:
            ready, _, _ = select.select([pipe], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                return Survey(model.path, f"pyBullet did not load and step it within {timeout:g} s")
            chunk = os.read(pipe.fileno(), 1 << 16)
            if not chunk:
                break
            chunks.append(chunk)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        return Survey(model.path, f"pyBullet crashes loading it (signal {os.WTERMSIG(status)}, pybullet "
                                  f"{_pybullet_version()})")
    try:
        return Survey(**json.loads(b"".join(chunks)))
    except (ValueError, TypeError):
        return Survey(model.path, f"the survey's process ended with status {os.WEXITSTATUS(status)} and no answer")


def _pybullet_version() -> str:
    from importlib import metadata

    try:
        return metadata.version("pybullet")
    except metadata.PackageNotFoundError:
        return "?"


def _survey_here(model: Model) -> Survey:
    import numpy as np
    import pybullet as p

    root = data_path()
    client = p.connect(p.DIRECT)
    try:
        p.setAdditionalSearchPath(str(root), physicsClientId=client)
        p.setGravity(0, 0, -10, physicsClientId=client)
        p.loadURDF("plane.urdf", physicsClientId=client)
        try:
            loaded = getattr(p, model.loader)(model.path, physicsClientId=client)
        except p.error as exc:
            return Survey(model.path, f"{model.loader} raises: {exc}")
        bodies = [loaded] if isinstance(loaded, int) else list(loaded)
        if not bodies:
            return Survey(model.path, f"{model.loader} loads no body")
        result = Survey(model.path, bodies=len(bodies))
        kinds, unreadable = set(), []
        for body in bodies:
            joints = p.getNumJoints(body, physicsClientId=client)
            result.links += joints + 1
            for j in range(joints):
                kind = p.getJointInfo(body, j, physicsClientId=client)[2]
                result.movable += kind in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC)
                result.fixed_joints += kind == p.JOINT_FIXED
            masses = [p.getDynamicsInfo(body, link, physicsClientId=client)[0] for link in range(-1, joints)]
            result.dynamic |= any(m > 0 for m in masses)
            for shape in p.getVisualShapeData(body, physicsClientId=client):
                name = _KINDS.get(shape[2], f"type {shape[2]}")
                kinds.add(name)
                result.spheres += name == "sphere"
                if name == "mesh" and not _readable(shape[4].decode("utf-8", "replace")):
                    unreadable.append(shape[4].decode("utf-8", "replace"))
        result.kinds = sorted(kinds)
        turned = _misreported(p, client, bodies) if model.loader == "loadMJCF" else ""
        if turned:
            result.unusable = (f"getVisualShapeData gives {turned} the identity frame, while pyBullet collides and draws it "
                               "along another axis (its collision box says so, as pyBullet's own picture does: an MJCF "
                               f"`fromto` shape, pybullet {_pybullet_version()}): a program drawing what pyBullet's calls "
                               "say draws it turned, so no right program can be written from them")
            return result
        if unreadable:
            result.unusable = f"trimesh cannot read its visual mesh {Path(unreadable[0]).name}"
            return result
        if not kinds:
            result.unusable = "it has no visual shape: nothing to draw"
            return result
        _lift(p, client, bodies)
        start = _frames(p, client, bodies)
        for step in range(SURVEY_STEPS):
            for body in bodies:
                _drive(p, client, body, step)
            p.stepSimulation(physicsClientId=client)
        end = _frames(p, client, bodies)
        result.moved = float(np.max(np.abs(end - start), initial=0.0))
        if not np.isfinite(result.moved):
            result.unusable = "its simulation leaves some frame at NaN or infinity"
        elif result.moved < STILL:
            result.unusable = f"nothing moves ({result.moved:.2g} m over {SURVEY_STEPS} steps)"
        return result
    finally:
        p.disconnect(physicsClientId=client)


_KINDS = {2: "sphere", 3: "box", 4: "cylinder", 5: "mesh", 6: "plane", 7: "capsule"}


def _misreported(p, client, bodies) -> str:
    """The first link of an MJCF model whose one visual shape, a long cylinder or capsule, does not fit its
    collision box ("body 1 link 0's capsule"), "" for none: pyBullet 3.2.7 gives MJCF ``fromto``
    shapes the identity frame in ``getVisualShapeData`` while it turns them along the axis for collision and for
    its own picture (measured on ``mjcf/cylinder_fromtoX.xml``: 19x9 pixels wide in pyBullet's picture, drawn
    9x19 by its visual frame)."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    for body in bodies:
        shapes: dict[int, list] = {}
        for shape in p.getVisualShapeData(body, physicsClientId=client):
            shapes.setdefault(shape[1], []).append(shape)
        for link, found in shapes.items():
            if len(found) != 1 or found[0][2] not in (p.GEOM_CYLINDER, p.GEOM_CAPSULE):
                continue
            length, radius = found[0][3][0], found[0][3][1]
            half = np.array([radius, radius, length / 2 + (radius if found[0][2] == p.GEOM_CAPSULE else 0.0)])
            if half[2] < 1.5 * radius:
                continue  # not long enough for its axis to show in a box
            if link == -1:
                orn = p.getBasePositionAndOrientation(body, physicsClientId=client)[1]
            else:
                orn = p.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=client)[5]
            turn = Rotation.from_quat(orn) * Rotation.from_quat(found[0][6])
            claimed = np.abs(turn.as_matrix()) @ half
            low, high = (np.asarray(v) for v in p.getAABB(body, link, physicsClientId=client))
            boxed = (high - low) / 2
            # An MJCF geom is its visual and its collision shape at once: the box its visual frame claims must
            # fit the collision box (which has a margin more), and lie along its longest axis
            longest = np.argmax(claimed) != np.argmax(boxed) and boxed.max() > 1.2 * np.sort(boxed)[1]
            if longest or np.any(claimed - boxed > 0.2 * claimed.max()):
                where = "base" if link == -1 else f"link {link}"
                return f"body {body} {where}'s {_KINDS[found[0][2]]}"
    return ""


def _readable(path: str) -> bool:
    try:
        import trimesh

        return len(trimesh.load(path, force="mesh").vertices) > 0
    except Exception:  # noqa: BLE001 - any reader failure means the programs cannot draw it
        return False


def _frames(p, client, bodies):
    import numpy as np

    rows = []
    for body in bodies:
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        rows.append([*pos, *(0.1 * np.asarray(orn))])
        for link in range(p.getNumJoints(body, physicsClientId=client)):
            pos, orn = p.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=client)[4:6]
            rows.append([*pos, *(0.1 * np.asarray(orn))])
    return np.array(rows)


def _lift(p, client, bodies) -> None:
    """Stand the bodies that can move on the ground, :data:`LIFT` above it, as the programs do."""
    lows = []
    movable = []
    for body in bodies:
        joints = p.getNumJoints(body, physicsClientId=client)
        if joints == 0 and p.getDynamicsInfo(body, -1, physicsClientId=client)[0] == 0:
            continue  # a static body (a floor, a shelf) stays where its file puts it
        movable.append(body)
        for link in range(-1, joints):
            low = p.getAABB(body, link, physicsClientId=client)[0][2]
            if abs(low) < 1e3:
                lows.append(low)
    if not lows:
        return
    rise = LIFT - min(lows)
    for body in movable:
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        p.resetBasePositionAndOrientation(body, [pos[0], pos[1], pos[2] + rise], orn, physicsClientId=client)


def _drive(p, client, body, step: int) -> None:
    import math

    for j in range(p.getNumJoints(body, physicsClientId=client)):
        info = p.getJointInfo(body, j, physicsClientId=client)
        if info[2] not in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC):
            continue
        low, high = info[8], info[9]
        middle, reach = ((low + high) / 2, 0.4 * (high - low)) if high > low else (0.0, 0.5)
        target = middle + reach * math.sin(2 * math.pi * 0.5 * step / 240 + j)
        p.setJointMotorControl2(body, j, p.POSITION_CONTROL, targetPosition=target, force=info[10] if info[10] > 0 else 50,
                                physicsClientId=client)
