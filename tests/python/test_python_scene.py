"""beamstops.Scene: namelist <-> Scene round trips, agreement with the program's own reader."""

from __future__ import annotations

import dataclasses
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

import beamstops
from beamstops import Scene, engine

from conftest import INPUT, ROOT


def test_the_package_is_the_installed_one() -> None:
    here = Path(beamstops.__file__).resolve()
    assert ROOT / "wrap" not in here.parents, f"tests import the source tree's package: {here}"
    assert beamstops._engine.__file__  # the compiled extension is there


def write(tmp_path: Path, text: str, name: str = "scene.nml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_namelist_without_groups_is_refused_not_read_as_the_paper_scene(tmp_path: Path) -> None:
    for text in ("! nothing but a comment\n", "", "time dt=1e-5 /\n", "&time dt=1e-5 /\nbeta = 0.3\n"):
        path = write(tmp_path, text)
        with pytest.raises(ValueError) as caught:
            Scene.from_namelist(path)
        assert str(path) in str(caught.value)
        assert "no namelist group" in str(caught.value) or "text outside any group" in str(caught.value)
    # the line is quoted
    path = write(tmp_path, "&beam length=2 /\ntime dt=1e-5 /\n")
    with pytest.raises(ValueError, match="line 2: text outside any group: `time dt=1e-5 /`"):
        Scene.from_namelist(path)
    # the smallest scene file: an empty group gives the paper's scene
    assert Scene.from_namelist(write(tmp_path, "&time /\n")) == Scene(file="scene.h5")


def test_scene_text_scene_is_the_identity_for_every_key() -> None:
    for scene in SCENES + [Scene(elements=30, nodes=(10, 20, 30), lower=(-0.002, -0.002, -0.004), upper=0.003,
                                 checkpoint_every=7)]:
        assert Scene.from_text(scene.to_text()) == scene
        assert Scene.from_text(scene.to_text()).to_text() == scene.to_text()
    # every key the engine reads is a field or a route
    fields = {f.name for f in dataclasses.fields(Scene)}
    for group, keys in beamstops.scene.GROUPS.items():
        for key in keys:
            assert key in fields or key in beamstops.scene.ROUTES, (group, key)


SCENES = [
    Scene(),
    Scene(file="out.h5", t_end=0.3, dt=1 / 30000, beta=0.25, snapshot_every=7, record_every=3),
    Scene(law="compliance", stiffness_per_mass=1e8, beta=0.25, dt=5e-6, load_rule="paper", start="euler",
          file="c.h5"),
    Scene(law="none", length=0.1 + 0.2, k2=1 / 3, mass_per_length=2.0 ** -30, amplitude=-1e-300, omega=0.0,
          lower=-1e-9, upper=123456.789, elements=1, allow_unstable=True, file="n.h5", max_output_gb=0.5),
]


@pytest.mark.parametrize("scene", SCENES, ids=range(len(SCENES)))
def test_scene_namelist_scene_round_trip_is_exact(scene: Scene, tmp_path: Path) -> None:
    path = tmp_path / "scene.nml"
    scene.to_namelist(path)
    back = Scene.from_namelist(path)
    expected = scene if scene.file is not None else scene.replace(file="scene.h5")
    assert back == expected, back.differences(expected)
    # and the program reads the very same values
    assert engine.read_namelist(path) == expected


@pytest.mark.parametrize("name", sorted(p.name for p in INPUT.glob("*.nml")))
def test_shipped_inputs_read_as_the_program_reads_them(name: str, tmp_path: Path) -> None:
    scene = Scene.from_namelist(INPUT / name)
    assert scene.differences(engine.read_namelist(INPUT / name)) == ""
    # namelist -> Scene -> namelist -> Scene
    scene.to_namelist(tmp_path / name)
    assert Scene.from_namelist(tmp_path / name) == scene


# Namelist texts the program accepts, written in every way its reader allows.
ACCEPTED = [
    "&time dt=1e-5 /",
    "&TIME DT=1E-5, T_END=1 /",
    "&time dt=1d-5 /",
    "&time dt=.5e-4, beta=.25 /",
    "&time t_end=1 dt=1e-5 /",
    "&time dt = 1e-5 ! a comment / not the end\n beta=0.3 /",
    "&time dt=1e-5; beta=0.3 /",
    "&time dt=1e-5 /\n&end\n&beam length=2 /",
    "&time\n dt=1e-5\n&end\n&beam length=2 /",
    "&time\n dt=1e-5\n $END ! old style\n&beam length=2 /",
    "$time dt=1e-5 $end",
    "&time dt=1 &end",
    "&mesh elements=+19 /",
    "&time allow_unstable=T, beta=0.1, dt=1e-5 /",
    "&time allow_unstable=.t. /",
    "&stops law=' signorini' /",
    "&stops law='signorini ', lower=-0.05 /",
    '&time load_rule="paper", start="euler" /',
    "&stops law='compliance', stiffness=1e7 /",
    "&stops law='compliance', stiffness_per_mass=1e8 /",
    "&beam youngs_modulus=2e11, density=8e3, outer_diameter=0.01, wall_thickness=5e-4 /\n"
    "&stops law='compliance', stiffness=1e8 /",
    "&beam length=2, k2=300 /",
    "&output file='x y.h5', record_every=10, snapshot_every=100, max_output_gb=0.1 /",
    "&beam length=2 /\n&support amplitude=0.1 omega=20 /\n&mesh elements=7 /\n",
]


@pytest.mark.parametrize("text", ACCEPTED)
def test_from_namelist_accepts_what_the_program_accepts_with_the_same_values(text: str, tmp_path: Path) -> None:
    path = write(tmp_path, text + "\n")
    reference = engine.read_namelist(path)
    scene = Scene.from_namelist(path)
    assert scene.differences(reference) == ""


# Texts the program refuses: the Python reader refuses them with the program's own message.
REFUSED = [
    ("&beams length=1 /", ["&beams", "unknown group"]),
    ("&time dtt=1e-5 /", ["&time", "dtt"]),
    ("&time dt=abc /", ["&time", "abc"]),
    ("&time dt= /", ["&time dt has no value", "allowed: dt = a real number"]),
    # a null after the value (two commas) is an empty value, like `nodes = 2*`
    ("&time dt=1e-5,, /", ["&time dt=1e-5,, has an empty value", "allowed: dt = a real number"]),
    ("&time dt=1.0_8 /", ["&time", "_8"]),
    ("&time dt=1e-5, 2e-5 /", ["&time", "2e-5"]),
    ("&time dt=1e-5 /\n&time dt=2e-5 /", ["&time", "twice"]),
    ("&stops law='signorini' law='none' /", ["&stops law is given twice"]),
    ("&mesh elements=19.0 /", ["&mesh"]),
    ("&mesh elements=2147483648 /", ["&mesh elements=2147483648 is out of range", "1 <= elements <= 1000000"]),
    ("&output record_every=-2147483649 /", ["&output record_every=-2147483649 is out of range", "record_every >= 1"]),
    ("&output snapshot_every=2147483648 /", ["is out of range", "snapshot_every >= 0 (0: none), and at most 2147483647"]),
    ("&ensemble seed=-9999999999 /", ["&ensemble seed=-9999999999 is out of range",
                                      "a whole number from -2147483648 to 2147483647"]),
    ("&mesh elements=2147483648a /", ["&mesh elements=2147483648a is malformed", "a whole number"]),
    ("&stops nodes=5, 99999999999999999999 lower=-0.1 upper=0.1 /",
     ["&stops nodes=5, 99999999999999999999 is out of range", "1 <= nodes <= elements = 19"]),
    ("&damping ratio=0.01 modes=1, -99999999999999999999 /",
     ["&damping modes=1, -99999999999999999999 is out of range", "1 <= mode <= 2 elements = 38"]),
    # the value that marks a list element as not given, given: refused, not taken as not given
    ("&stops nodes=-2147483647 lower=-0.1 upper=0.1 /", ["&stops nodes(1) = -2147483647 is out of range"]),
    ("&damping ratio=0.01 modes=-2147483647, 2 /", ["&damping modes = -2147483647, 2 is out of range"]),
    ("&stops lower=-1.7976931348623157e308 /", ["&stops lower = -1.797693134862315", "is out of range", "-1e+06 <= lower"]),
    ("&beam k2=-1.7976931348623157e308 /", ["&beam k2 = -1.797693134862315", "is out of range"]),
    ("&time dt=-1e-5 /", ["&time dt = -1e-05", "allowed"]),
    ("&time dt=nan /", ["&time dt", "allowed"]),
    ("&time beta=0.7 /", ["&time beta", "0.5"]),
    ("&stops lower=0.05 /", ["&stops lower", "allowed"]),
    ("&stops law='glue' /", ["&stops law", "signorini"]),
    ("&stops law='compliance' /", ["&stops", "stiffness"]),
    ("&stops law='compliance', stiffness=-1 /", ["&stops stiffness", "> 0"]),
    ("&stops law='signorini', stiffness=1e7 /", ["&stops stiffness = 1e+07", "law = 'compliance'"]),
    ("&damping modes=1, 3 /", ["&damping modes = 1, 3", "without ratio"]),
    ("&time load_rule=' paper' /", ["&time load_rule"]),
    ("&beam youngs_modulus=2e11 /", ["&beam", "density"]),
    ("&beam k2=1, youngs_modulus=2e11, density=8e3, outer_diameter=0.01, wall_thickness=5e-4 /", ["&beam", "k2"]),
    ("&beam youngs_modulus=2e11, density=8e3, outer_diameter=0.01, wall_thickness=0.006 /",
     ["&beam wall_thickness"]),
    ("&output file='' /", ["&output file"]),
    ("&output record_every=0 /", ["&output record_every", ">= 1"]),
    ("&time dt=1e-9 /", ["max_output_gb"]),
    ("&time dt=1e-5 /\n\x00\x01\n", ["binary"]),
    ("&damping mass_coefficient=inf /", ["&damping mass_coefficient = Inf is out of range", "<= 1.69e+08 1/s"]),
    ("&damping stiffness_coefficient=1e300 /", ["&damping stiffness_coefficient = 1e+300 is out of range"]),
    ("&time dt=1e-170, t_end=1e-170 /", ["&time t_end = 1e-170", "1e-15 <= t_end"]),
    ("&stops law='compliance', stiffness=1e5, stiffness_per_mass=1e6 /", ["both given"]),
    # a group name joined to what follows: gfortran did not find the group and kept every default
    ("&time=1e-5, beta=0.3 /", ["line 1: group &time is followed by `=1e-5, beta=0.3 /` with no blank",
                                "allowed: a blank after the group name"]),
    ("&output='x.h5' /", ["group &output is followed by"]),
    # a value with no key name before its =: the message named an empty key ('allowed:  = a real number')
    ("&time =1e-5 /", ["&time =1e-5 is malformed: no key name before =", "the keys of &time: dt, t_end"]),
    ("&output ='x.h5' /", ["&output ='x.h5' is malformed: no key name", "the keys of &output: file"]),
    ("&time (1)=2 /", ["&time (1)=2 is malformed: no key name before ="]),
    ("&time dt=1e-5, =2 /", ["&time =2 is malformed: no key name before ="]),
    # a key that is not a whole word: read as its last part (`unknown key t`) or blamed on the value before
    ("&time d-t=2 /", ["&time d-t=2 is malformed: `d-t` before = is not a key name", "keys of &time"]),
    ("&time dt=1e-5 =2 /", ["&time dt=1e-5 =2 is malformed: `1e-5` before = is not a key name"]),
]


@pytest.mark.parametrize(("text", "needles"), REFUSED, ids=[r[0][:40] for r in REFUSED])
def test_from_namelist_refuses_what_the_program_refuses(text: str, needles: list[str], tmp_path: Path) -> None:
    path = write(tmp_path, text + "\n")
    with pytest.raises(ValueError) as program:
        engine.read_namelist(path)
    with pytest.raises(ValueError) as python:
        Scene.from_namelist(path)
    assert str(python.value) == str(program.value)
    assert str(path) in str(python.value)
    for needle in needles:
        assert needle in str(python.value), (needle, str(python.value))


def test_keywords_out_of_range_are_refused_with_the_engines_message() -> None:
    with pytest.raises(ValueError, match=r"^scene: &damping mass_coefficient = Inf is out of range; allowed: 0 <= "):
        Scene(mass_coefficient=float("inf"))
    with pytest.raises(ValueError, match=r"^scene: &damping stiffness_coefficient = 1e\+100 is out of range"):
        Scene().replace(stiffness_coefficient=1e100)
    with pytest.raises(ValueError, match=r"^scene: &time dt = 1e-170 is out of range; allowed: 1e-15 <= dt"):
        Scene(dt=1e-170)
    assert Scene(mass_coefficient=1e8, stiffness_coefficient=7.0).mass_coefficient == 1e8


def test_missing_file_is_an_os_error(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        Scene.from_namelist(tmp_path / "nowhere.nml")


def test_material_and_stiffness_routes_match_the_programs(tmp_path: Path) -> None:
    material = dict(youngs_modulus=2e11, density=8e3, outer_diameter=0.01, wall_thickness=5e-4)
    path = write(tmp_path, "&beam " + ", ".join(f"{k}={v!r}" for k, v in material.items()) + " /\n"
                 "&stops law='compliance', stiffness=1e8 /\n")
    scene = Scene().replace(law="compliance", stiffness=1e8, file="scene.h5", **material)
    assert scene == Scene.from_namelist(path) == engine.read_namelist(path)
    # SPEC §2: rho S = 0.11938 kg/m, k2 = 282.84 m^4/s^2 for the paper's pipe
    assert scene.mass_per_length == pytest.approx(0.11938, rel=1e-4)
    assert scene.k2 == pytest.approx(282.84, rel=2e-4)
    assert scene.stiffness_per_mass == 1e8 / scene.mass_per_length


def test_replace_and_keyword_checks() -> None:
    scene = Scene().replace(dt=1e-6, beta=0.25)
    assert (scene.dt, scene.beta, Scene().dt) == (1e-6, 0.25, 5e-5)
    with pytest.raises(TypeError, match="unknown scene key"):
        Scene().replace(timestep=1e-6)
    with pytest.raises(ValueError, match="&mesh elements = 19.5 is malformed; allowed: elements = a whole number"):
        Scene(elements=19.5)
    with pytest.raises(ValueError, match="&time dt = '1e-5' is malformed; allowed: dt = a real number"):
        Scene(dt="1e-5")
    with pytest.raises(ValueError, match=r"&time allow_unstable = 1 is malformed; allowed: allow_unstable = \.true\."):
        Scene(allow_unstable=1)
    with pytest.raises(TypeError, match="dt cannot hold"):
        Scene(dt={"a": 1})
    # a numpy scalar or 0-d array is its one value, as a number is
    assert Scene(dt=np.array(1e-6), elements=np.array(4), law=np.array("none")) == Scene(dt=1e-6, elements=4,
                                                                                        law="none")
    assert Scene(dt=np.float64(1e-6), allow_unstable=np.bool_(True)) == Scene(dt=1e-6, allow_unstable=True)
    with pytest.raises(ValueError, match="&stops law = 'glue'"):
        Scene(law="glue")
    with pytest.raises(ValueError, match="&beam density is missing"):
        Scene().replace(youngs_modulus=2e11)
    with pytest.raises(ValueError, match="stiffness and stiffness_per_mass are both given; allowed: one of them"):
        Scene().replace(law="compliance", stiffness=1e8, stiffness_per_mass=1e8)
    assert dataclasses.is_dataclass(scene) and hash(scene) == hash(Scene().replace(dt=1e-6, beta=0.25))


def test_any_file_name_goes_through(tmp_path: Path) -> None:
    folder = tmp_path / "dossier é ü"
    folder.mkdir()
    path = write(folder, "&time dt=1e-5 /\n", name="scène.nml")
    assert Scene.from_namelist(path) == engine.read_namelist(path) == Scene(dt=1e-5, file="scène.h5")
    with pytest.raises(ValueError, match="scène.nml: &time dt = -1"):
        Scene.from_text("&time dt=-1 /", str(path))


@pytest.mark.parametrize("text, kind", [(123, "int"), (b"&time /", "bytes"), (None, "NoneType")])
def test_from_text_of_something_not_text_is_a_type_error(text: object, kind: str) -> None:
    with pytest.raises(TypeError, match=rf"^Scene.from_text: text must be a str of namelist text, not {kind}\b"):
        Scene.from_text(text)  # type: ignore[arg-type]


@pytest.mark.parametrize("changes, kind", [({"dt": None}, TypeError), ({"elements": []}, TypeError),
                                           ({"file": "x\ny.h5"}, ValueError), ({"law": "sig\tnorini"}, ValueError)])
def test_none_empty_or_control_characters_are_refused(changes: dict, kind: type) -> None:
    """None or [] for a key whose default is a value read as 'the default' (dt=None ran at
    5e-5 s), and a line break in a text became a blank ('x\\ny.h5' wrote 'x y.h5')."""
    with pytest.raises(kind, match="scene key"):
        Scene(**changes)
    assert Scene(file=None).file is None and Scene(nodes=()).nodes == ()


@pytest.mark.parametrize("changes, allowed", [
    ({"dt": [1e-5]}, "&time dt(1:1) = 1e-05 is malformed; allowed: dt = a real number, e.g. 1e-5"),
    ({"dt": [[1e-5]]}, "&time dt(1:1) = 1e-05 is malformed; allowed: dt = a real number, e.g. 1e-5"),
    ({"dt": (1e-5, 2e-5)}, "&time dt(1:2) = 1e-05, 2e-05 is malformed; allowed: dt = a real number"),
    ({"elements": [7]}, "&mesh elements(1:1) = 7 is malformed; allowed: elements = a whole number"),
    ({"modes": [2]}, "&mesh modes(1:1) = 2 is malformed; allowed: modes = a whole number"),
    ({"law": ["none"]}, "&stops law(1:1) = 'none' is malformed; allowed: law = a quoted text"),
    ({"allow_unstable": [True]}, "&time allow_unstable(1:1) = .true. is malformed; allowed: allow_unstable = .true. "
                                 "or .false."),
])
def test_a_list_for_a_key_of_one_value_is_refused_by_the_engine(changes: dict, allowed: str) -> None:
    """Scene(dt=[1e-5]) and Scene(dt=[[1e-5]]) were written `dt = 1e-05` and ran at 1e-5 s: a list
    is written with its section, which the engine refuses on a key of one value."""
    with pytest.raises(ValueError, match="^scene: " + re.escape(allowed)):
        Scene(**changes)
    with pytest.raises(ValueError, match="^scene: " + re.escape(allowed)):
        Scene().replace(**changes)
    np = pytest.importorskip("numpy")
    key, value = next(iter(changes.items()))
    if not isinstance(value[0], (str, bool)):
        with pytest.raises(ValueError, match="^scene: " + re.escape(allowed)):
            Scene(**{key: np.array(value)})


def test_lists_for_list_keys_are_read_as_before() -> None:
    scene = Scene(nodes=[5, 10], lower=(-0.1, -0.2), upper=[0.1], ratio=[0.01], damping_modes=[1, 3])
    assert scene.nodes == (5, 10) and scene.lower == (-0.1, -0.2) and scene.upper == (0.1, 0.1)
    assert scene.ratio == (0.01, 0.01) and scene.damping_modes == (1, 3)
    assert Scene(nodes=[[5, 10]]).nodes == (5, 10)
    assert scene.replace(nodes=(4, 8, 12), lower=[-0.1], upper=[0.1]).nodes == (4, 8, 12)
    with pytest.raises(ValueError, match=r"^scene: &stops nodes has 1001 values, out of range"):
        Scene(nodes=list(range(1, 1002)), elements=2000)


def test_replace_leaves_out_a_spring_or_modes_the_change_makes_useless() -> None:
    """The engine refuses a spring without law 'compliance' and &damping modes without ratio:
    a change of law or of the damping's form must not carry them along."""
    spring = Scene(law="compliance", stiffness_per_mass=1e8, beta=0.25, dt=5e-6)
    plain = spring.replace(law="signorini")
    assert plain.law == "signorini" and "stiffness_per_mass" not in plain.to_text()
    assert plain.replace(law="compliance", stiffness_per_mass=1e7).stiffness_per_mass == 1e7
    ratio = Scene(ratio=(0.01, 0.02), damping_modes=(1, 3))
    coefficients = ratio.replace(mass_coefficient=0.1)
    assert coefficients.mass_coefficient == 0.1 and "modes" not in coefficients.groups()["damping"]
    with pytest.raises(ValueError, match="without ratio"):
        Scene().replace(damping_modes=(1, 3))


def test_the_engine_drops_a_carried_key_that_does_nothing_and_refuses_one_given_anew() -> None:
    """The rule of idle keys is the engine's: Scene.replace only says which keys it carries over."""
    spring = "&stops law = 'signorini', stiffness_per_mass = 1e8 /\n"
    with pytest.raises(ValueError, match="stiffness_per_mass = .* only with law = 'compliance'"):
        engine.canonical(spring)
    assert "stiffness_per_mass" not in engine.canonical(spring, carried=["stops:stiffness_per_mass"])
    # carried keys are dropped only where they do nothing: with the compliance law the spring stays
    compliance = "&stops law = 'compliance', stiffness_per_mass = 1e8 /\n&time beta = 0.25, dt = 5e-6 /\n"
    assert Scene.from_text(engine.canonical(compliance, carried=["stops:stiffness_per_mass"])).stiffness_per_mass == 1e8
    modes = "&damping modes = 1, 3 /\n"
    with pytest.raises(ValueError, match="without ratio"):
        engine.canonical(modes, carried=["stops:stiffness_per_mass"])
    assert "modes" not in Scene.from_text(engine.canonical(modes, carried=["damping:modes"])).groups()["damping"]
    with pytest.raises(ValueError, match="only with law = 'compliance'"):
        Scene(law="compliance", stiffness_per_mass=1e8, beta=0.25, dt=5e-6).replace(law="signorini", stiffness=1e6)


@pytest.mark.parametrize("value", [123, 1.5, True, b"out.h5", ["out.h5"], np.int64(7)])
def test_the_output_file_is_a_str_or_a_path(value: object) -> None:
    """Scene(file=123) was written `file = 123`, which the reader took for the name '123'; the file
    is a str or an os.PathLike, and any other type a TypeError naming the key."""
    with pytest.raises(TypeError, match=r"^scene key file = .*: allowed: a str or an os\.PathLike"):
        Scene(file=value)
    with pytest.raises(TypeError, match=r"^scene key file = .*: allowed: a str or an os\.PathLike"):
        Scene().replace(file=value)
    assert Scene(file=Path("out dir") / "a.h5").file == "out dir/a.h5" == Scene(file="out dir/a.h5").file
    assert Scene(file="a.h5").replace(file=None).file is None


@pytest.mark.parametrize("changes, message", [
    ({"elements": 10**5000}, "&mesh elements = 1000000000"),     # beyond Python's int-to-str limit
    ({"elements": -10**5000}, "&mesh elements = -1000000000"),
    ({"nodes": [10**5000]}, "&stops nodes(1:1) = 1000000000"),
    ({"dt": __import__("fractions").Fraction(10**400)}, "&time dt = Inf is out of range"),  # beyond the doubles
    ({"dt": np.nan}, "&time dt = NaN is out of range"),
    ({"seed": np.int64(2**40)}, "&ensemble seed = 1099511627776 is out of range"),
])
def test_huge_values_reach_the_engines_range_check(changes: dict, message: str) -> None:
    """A whole number beyond Python's limit of 4300 digits ended in Python's own ValueError
    ('Exceeds the limit (4300 digits) for integer string conversion'), a Fraction beyond the
    doubles in an OverflowError: the engine's reader refuses them with the key's range."""
    with pytest.raises(ValueError, match="^scene: " + re.escape(message)):
        Scene(**changes)


@pytest.mark.parametrize("call", ["from_text", "replace", "validate", "stability"])
def test_a_source_that_is_not_text_is_a_type_error(call: str) -> None:
    """The name messages start with went to os.fsencode: 'expected str, bytes or os.PathLike object'."""
    scene = Scene(t_end=0.01)
    calls = {"from_text": lambda: Scene.from_text("&time /", 5), "replace": lambda: scene.replace(_source=5, dt=1e-5),
             "validate": lambda: scene.validate(5), "stability": lambda: beamstops.stability(scene, 5)}
    with pytest.raises(TypeError, match=r"^source = 5: allowed: a str"):
        calls[call]()
    with pytest.raises(TypeError, match=r"^path = None: allowed: a str or an os\.PathLike"):
        Scene.from_namelist(None)  # type: ignore[arg-type]


def test_to_namelist_writes_over_its_own_scenes_only(tmp_path: Path) -> None:
    """Scene.to_namelist wrote over anything at its path, through a symbolic link too: a run's
    output, a hand-written namelist. It writes over an empty file or a scene it wrote before only,
    whole, as every other file beamstops writes."""
    own = tmp_path / "own.nml"
    Scene(dt=1e-5).to_namelist(own)
    Scene(dt=2e-5).to_namelist(own)
    assert Scene.from_namelist(own).dt == 2e-5
    output = tmp_path / "run.h5"
    output.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(100))
    hand = tmp_path / "hand.nml"
    hand.write_text("&time dt = 1e-5 /\n")
    link = tmp_path / "link.nml"
    link.symlink_to(hand)
    for path in (output, hand, link):
        before = path.read_bytes()
        with pytest.raises(OSError, match=re.escape(path.name)):
            Scene().to_namelist(path)
        assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hand.nml", "link.nml", "own.nml", "run.h5"]


def test_the_constructor_reads_keys_as_replace_does() -> None:
    """Scene(dtt=1e-5) gave Python's bare 'unexpected keyword argument' and Scene(youngs_modulus=...)
    refused a key that replace() and the namelist take: the constructor now names the allowed keys
    and resolves a route as replace() does."""
    with pytest.raises(TypeError, match=r"unknown scene key\(s\) dtt; allowed: .*\bdt\b"):
        Scene(dtt=1e-5)
    material = dict(youngs_modulus=2e11, density=8e3, outer_diameter=0.01, wall_thickness=5e-4)
    assert Scene(**material, elements=8) == Scene().replace(**material, elements=8) != Scene(elements=8)
    assert Scene(stiffness=1e6, law="compliance").stiffness_per_mass == \
        Scene().replace(stiffness=1e6, law="compliance").stiffness_per_mass
    assert Scene(dt=1e-5) == Scene().replace(dt=1e-5)


@pytest.mark.parametrize("file", ["a!b.h5", "x &time dt = 1 /", 'say "hi" !', "x $statistics bins = 5 $end"])
def test_a_quoted_value_hides_no_group_after_it(file: str, tmp_path: Path, program: str) -> None:
    # gfortran looked for each group through the whole text, the groups before it read as
    # comments: a `!` in &output file hid every later group, a quoted `&time` was taken for &time
    scene = Scene(file=file, bins=3, seed=7, dt=1e-4)
    assert (scene.file, scene.bins, scene.seed, scene.dt) == (file, 3, 7, 1e-4)
    text = f"&output file = '{file}' /\n&statistics bins = 3 /\n&ensemble seed = 7 /\n&time dt = 1e-4 /\n"
    assert Scene.from_text(text) == scene
    path = write(tmp_path, text)
    assert Scene.from_namelist(path) == scene
    shown = subprocess.run([program, "info", str(path)], capture_output=True, text=True, check=True).stdout
    assert re.search(r"^&time dt +0\.0001 s$", shown, re.M) and re.search(r"^ +seed +7 *$", shown, re.M)


@pytest.mark.parametrize("changes", [{"damping_modes": [1, 2]}, {"damping_modes": np.array([1, 2])},
                                     {"stiffness_per_mass": 0}, {"stiffness_per_mass": np.float64(0.0)},
                                     {"mass_coefficient": np.float32(0.0), "ratio": 0.1}, {"beta": np.float64(0.5)}])
def test_a_default_in_another_dress_is_the_default(changes: dict) -> None:
    # a list for the default tuple, a numpy scalar or an int for the default real: the default,
    # left out as the default itself is (they were written, and the engine refused `modes` without
    # ratio, a spring without the compliance law, or a Rayleigh coefficient beside the ratios)
    plain = {key: (tuple(value) if isinstance(value, (list, np.ndarray)) else float(value)) for key, value in changes.items()}
    assert Scene(**changes) == Scene(**plain) == Scene().replace(**changes)
    assert Scene().replace(**changes).differences(Scene().replace(**plain)) == ""


def test_replace_with_a_field_as_a_list_is_no_change() -> None:
    scene = Scene(nodes=(3, 9), lower=(-0.1, -0.2), upper=0.2, ratio=(0.01, 0.02), damping_modes=(1, 3))
    for field in dataclasses.fields(Scene):
        value = getattr(scene, field.name)
        if isinstance(value, tuple):
            assert scene.replace(**{field.name: list(value)}) == scene
            assert scene.replace(**{field.name: np.array(value)}) == scene
    assert Scene().replace(damping_modes=list(Scene().damping_modes)) == Scene()


def test_a_route_given_as_nothing_replaces_nothing() -> None:
    # `ratio=()` is the coefficients' form, which the scene has: its coefficients were dropped
    damped = Scene(mass_coefficient=1.0, stiffness_coefficient=1e-4)
    for nothing in ((), [], None, np.array([])):
        assert damped.replace(ratio=nothing) == damped
    spanned = Scene(nodes=(3, 9))
    assert spanned.replace(x=()) == spanned and spanned.replace(x=None) == spanned
    assert Scene(ratio=0.1).replace(ratio=()) == Scene()
