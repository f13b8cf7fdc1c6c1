"""Random edits of valid scenes give a valid scene or a clean one-line SceneError, nothing else."""

import copy
import tomllib

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from clutchocp.errors import SceneError
from clutchocp.scene import Scene, builtin_scene_dir
from clutchocp.scene.schema import PARTS

SCENES = {p.stem: tomllib.loads(p.read_text()) for p in builtin_scene_dir().glob("*.toml")}
UNITS = ["m", "mm", "um", "Pa", "MPa", "Pa s", "rpm", "rad/s", "kg", "kg m^2", "N m", "1/m^2", "deg", "s", "furlong", "", "N/mm", "kg/m^3"]

scalars = st.one_of(
    st.integers(min_value=-10**6, max_value=10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(),
    st.text(max_size=12),
    st.builds(lambda x, u: f"{x:g} {u}", st.floats(min_value=-1e9, max_value=1e9, allow_nan=False), st.sampled_from(UNITS)),
    st.sampled_from(["exact", "patir", "none", "inertia", "fixed", "constant", "masses", "massless", "greenwood_tripp"]),
)
values = st.one_of(scalars, st.lists(scalars, max_size=4), st.dictionaries(st.text(max_size=5), scalars, max_size=2))
known_keys = sorted({k for part in PARTS.values() for k in part.fields} | {k for part in PARTS.values() for v in part.variants.values() for k in v} | {"model"})


@st.composite
def edited_scene(draw):
    raw = copy.deepcopy(SCENES[draw(st.sampled_from(sorted(SCENES)))])
    for _ in range(draw(st.integers(min_value=1, max_value=3))):
        action = draw(st.sampled_from(["set", "delete_key", "delete_part", "new_part"]))
        part = draw(st.sampled_from(sorted(raw))) if raw else "scene"
        if action == "set" and isinstance(raw.get(part), dict):
            key = draw(st.one_of(st.sampled_from(known_keys), st.text(min_size=1, max_size=8)))
            raw[part][key] = draw(values)
        elif action == "delete_key" and isinstance(raw.get(part), dict) and raw[part]:
            raw[part].pop(draw(st.sampled_from(sorted(raw[part]))))
        elif action == "delete_part":
            raw.pop(part, None)
        else:
            raw[draw(st.one_of(st.sampled_from(sorted(PARTS)), st.text(min_size=1, max_size=8)))] = draw(values)
    return raw


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(edited_scene())
def test_random_edits_give_valid_scene_or_clean_error(raw):
    try:
        scene = Scene(raw)
    except SceneError as exc:
        message = str(exc)
        assert message and "\n" not in message
        assert "Traceback" not in message
    else:
        assert scene.name and scene.kind in ("engagement", "hvd", "static")
