"""tools/rust_layers.py, the layering check of the Rust crates: on small crates written here,
each test has one reference or cycle the check must find (or must not), and the repository's
own crates keep their declared order (crates/layers.toml)."""

from __future__ import annotations

import importlib.util
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("rust_layers", ROOT / "tools" / "rust_layers.py")
assert _spec is not None and _spec.loader is not None
rust_layers = importlib.util.module_from_spec(_spec)
sys.modules["rust_layers"] = rust_layers
_spec.loader.exec_module(rust_layers)

# The order of the small crates: model at the bottom, kinematics above it, loader on top.
LAYERS = ["model", "kinematics", "loader"]


def crate(tmp_path: Path, files: dict[str, str]) -> Path:
    """A crate at tmp_path/src with a model, a kinematics and a loader module; returns tmp_path."""
    src = tmp_path / "src"
    for name, text in {"lib.rs": "pub mod kinematics;\npub mod loader;\npub mod model;\n", **files}.items():
        path = src / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    for name in ("model.rs", "kinematics.rs", "loader.rs"):
        if not (src / name).exists() and not (src / name.replace(".rs", "/mod.rs")).exists():
            (src / name).write_text("pub struct Nothing;\n")
    return tmp_path


def run(tmp_path: Path, files: dict[str, str], **cfg: object) -> tuple[list[str], list[str]]:
    found, allowed, _ = rust_layers.check("c", {"src": "src", "layers": LAYERS, **cfg}, crate(tmp_path, files))
    return found, allowed


def test_an_upward_reference_inside_a_function_is_found(tmp_path: Path) -> None:
    found, _ = run(tmp_path, {"model.rs": "pub fn f() -> usize { crate::kinematics::count() }\n"})
    assert found == ["c: model.rs -> kinematics.rs: upward: model (layer 0) -> kinematics (layer 1)"]


def test_downward_references_comments_and_unit_tests_are_not_violations(tmp_path: Path) -> None:
    files = {
        "kinematics.rs": "use crate::model::Mechanism;\n",
        "model.rs": """\
            // crate::loader::load is named in a comment only
            pub struct Mechanism;
            #[cfg(test)]
            mod tests {
                use crate::loader::load;
            }
            """,
    }
    assert run(tmp_path, files) == ([], [])


def test_a_unit_test_module_shared_with_other_tests_is_still_a_test(tmp_path: Path) -> None:
    # `pub(crate) mod tests` shares a fixture with another module's tests (s17: A02's folded
    # pose); its loader use is a test's. The same text outside a test module is an upward edge.
    shared = """\
        pub struct Mechanism;
        #[cfg(test)]
        pub(crate) mod tests {
            use crate::loader::load;
        }
        """
    assert run(tmp_path, {"kinematics.rs": "", "model.rs": shared}) == ([], [])
    upward = "pub struct Mechanism;\nuse crate::loader::load;\n"
    assert run(tmp_path / "b", {"kinematics.rs": "", "model.rs": upward})[0]


def test_a_path_through_a_reexport_lands_in_the_file_that_defines_it(tmp_path: Path) -> None:
    # `crate::Workspace` is lib.rs's re-export of kinematics/ws.rs: the model may not use it.
    files = {
        "lib.rs": "pub mod kinematics;\npub mod loader;\npub mod model;\npub use kinematics::Workspace;\n",
        "kinematics/mod.rs": "mod ws;\npub use ws::Workspace;\n",
        "kinematics/ws.rs": "pub struct Workspace;\n",
        "model.rs": "use crate::{Workspace};\n",
    }
    found, _ = run(tmp_path, files)
    assert found == ["c: model.rs -> kinematics/ws.rs: upward: model (layer 0) -> kinematics (layer 1)"]


def test_a_method_given_to_a_lower_type_from_above_is_an_upward_reference(tmp_path: Path) -> None:
    # `Mechanism::new` written in the loader looks like the model's own: the model's type
    # then reaches up to the loader (and round, as the loader uses the model). A trait impl
    # there is the loader's own business.
    files = {
        "model.rs": "pub struct Mechanism;\n",
        "loader.rs": """\
            use crate::model::Mechanism;
            impl Mechanism {
                pub fn new() -> Self { Mechanism }
            }
            impl Default for Mechanism {
                fn default() -> Self { Mechanism }
            }
            """,
    }
    found, _ = run(tmp_path, files)
    assert found == [
        "c: model.rs -> loader.rs: upward: model (layer 0) -> loader (layer 2) "
        "(its `Mechanism` gets methods there: make them functions of `loader`)",
        "c: file cycle (2): loader.rs, model.rs",
        "c: module cycle (2): loader, model",
    ]


def test_use_groups_are_expanded(tmp_path: Path) -> None:
    files = {"model.rs": "use crate::{kinematics::{self, count as n}, loader::{load}};\n"}
    found, _ = run(tmp_path, files)
    assert [f.split(": ")[1] for f in found] == ["model.rs -> kinematics.rs", "model.rs -> loader.rs"]


def test_a_cycle_between_two_files_of_one_layer_is_found(tmp_path: Path) -> None:
    files = {
        "kinematics/mod.rs": "pub mod analogues;\npub mod position;\n",
        "kinematics/analogues.rs": "use super::position::singular;\npub fn u() {}\n",
        "kinematics/position.rs": "pub fn singular() { super::analogues::u() }\n",
    }
    found, _ = run(tmp_path, files)
    assert found == ["c: file cycle (2): kinematics/analogues.rs, kinematics/position.rs"]


def test_a_cycle_between_two_modules_through_different_files_is_found(tmp_path: Path) -> None:
    # model.rs -> kinematics/x.rs and kinematics/y.rs -> model.rs: no file cycle (x and y are
    # different files), but the modules model and kinematics reference each other. The upward
    # reference is a finding of the order; allowed, the module cycle it closes still is one.
    files = {
        "kinematics/mod.rs": "pub mod x;\npub mod y;\n",
        "kinematics/x.rs": "pub fn count() -> usize { 1 }\n",
        "kinematics/y.rs": "use crate::model::Mechanism;\n",
        "model.rs": "pub struct Mechanism;\npub fn f() -> usize { crate::kinematics::x::count() }\n",
    }
    found, _ = run(tmp_path, files)
    assert found == [
        "c: model.rs -> kinematics/x.rs: upward: model (layer 0) -> kinematics (layer 1)",
        "c: module cycle (2): kinematics, model",
    ]
    known = {"from": "model.rs", "to": "kinematics/x.rs", "why": "w", "until": "phase 9"}
    found, allowed = run(tmp_path, files, allow=[known])
    assert found == ["c: module cycle (2): kinematics, model"]
    assert len(allowed) == 1


def test_the_allow_list_lets_known_violations_pass_and_only_shrinks(tmp_path: Path) -> None:
    files = {"model.rs": "use crate::kinematics::count;\n"}
    known = {"from": "model.rs", "to": "kinematics.rs", "why": "w", "until": "phase 9"}
    found, allowed = run(tmp_path, files, allow=[known])
    assert found == []
    assert allowed == [
        "c: model.rs -> kinematics.rs: upward: model (layer 0) -> kinematics (layer 1)  [allowed: w; until phase 9]"
    ]
    # Once the reference is gone, the entry itself is a finding.
    found, _ = run(tmp_path, {"model.rs": "pub fn f() {}\n"}, allow=[known])
    assert found == ["c: allow-list entry matches nothing now, remove it: model.rs -> kinematics.rs"]


def test_an_allowed_cycle_must_name_exactly_the_files_still_in_it(tmp_path: Path) -> None:
    files = {
        "model/mod.rs": "pub mod a;\npub mod b;\npub mod c;\n",
        "model/a.rs": "use super::b::B;\npub struct A;\n",
        "model/b.rs": "use super::a::A;\npub struct B;\n",
        "model/c.rs": "pub struct C;\n",
    }
    cycle = {"cycle": ["model/a.rs", "model/b.rs", "model/c.rs"], "why": "w", "until": "phase 9"}
    found, allowed = run(tmp_path, files, allow=[cycle])
    assert found == ["c: model/c.rs is in no cycle now: remove it from its allow-list entry"]
    assert allowed == ["c: file cycle (2): model/a.rs, model/b.rs  [allowed: w; until phase 9]"]


def test_independent_modules_and_may_use(tmp_path: Path) -> None:
    # `kinematics | loader`: neither may use the other; `may_use` keeps loader off the model too.
    files = {"loader.rs": "use crate::kinematics::count;\nuse crate::model::Mechanism;\n"}
    found, _ = rust_layers.check(
        "c",
        {"src": "src", "layers": ["model", "kinematics | loader"], "may_use": {"loader": []}},
        crate(tmp_path, files),
    )[:2]
    assert found == [
        "c: loader.rs -> kinematics.rs: loader may use no other module",
        "c: loader.rs -> model.rs: loader may use no other module",
    ]


def test_a_module_outside_the_order_is_a_finding(tmp_path: Path) -> None:
    found, _ = run(tmp_path, {"lib.rs": "pub mod extra;\n", "extra.rs": "pub struct E;\n"})
    assert found == ["c: module `extra` is in no layer of the declared order"]


@pytest.mark.parametrize("name", ["planardyn", "planardyn-py", "planardyn-wasm"])
def test_the_crates_keep_their_declared_layers(name: str) -> None:
    config = rust_layers.tomllib.loads((ROOT / "crates" / "layers.toml").read_text())
    found, _, _ = rust_layers.check(name, config[name], ROOT)
    assert found == []
