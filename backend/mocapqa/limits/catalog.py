"""Which limits model a check uses: the one definition of the model choice.

A choice is a **name**. ``"default"`` is the shipped choice of
:func:`~mocapqa.limits.storage.load_default_model` (the canonical model, or a shipped per-rig
model where it is measurably better); every shipped file is also choosable by its stem
(``"canonical"``, ``"bandai"``, ``"character_creator"``, ``"cmu"``); and a model built with
``mocapqa limits build`` becomes choosable once registered (``mocapqa limits register MODEL.npz
NAME``), which copies it to ``<data folder>/limits_models/NAME.npz``. The API (a shoot's
``limits_model``), the CLI (``--model NAME``, ``limits models``) and the UI (the shoot view's
picker, filled from ``GET /api/v1/limits-models``) all go through :class:`ModelCatalog`.
"""

from __future__ import annotations

import functools
import os
import re
import shutil
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mocapqa.errors import ConflictError, LimitsFileError, OptionError

if TYPE_CHECKING:
    from collections.abc import Mapping

    from mocapqa.core.motion import Skeleton
    from mocapqa.limits.model import LimitsModel

# The models (and scipy under them) are imported when one is read, not with the catalog: the
# run options check a model's name through it, and a resumed batch that analyses nothing
# should not pay for them (docs/batch.md).

__all__ = [
    "DEFAULT_MODEL",
    "MODELS_FOLDER",
    "MODEL_NAME_PATTERN",
    "ModelCatalog",
    "ModelEntry",
    "check_model_name",
]

DEFAULT_MODEL = "default"
"""The shipped choice per rig (:func:`~mocapqa.limits.storage.load_default_model`)."""
MODELS_FOLDER = "limits_models"
"""Folder of registered models, under the data folder."""
MODEL_NAME_PATTERN = r"^[a-z0-9][a-z0-9_-]{0,63}$"
"""A model name: lower-case letters, digits, ``_`` and ``-``, up to 64 characters."""
_NAME = re.compile(MODEL_NAME_PATTERN)


@dataclass(frozen=True, slots=True)
class ModelEntry:
    """One choosable model.

    Parameters
    ----------
    name : str
        What a shoot or ``--model`` names.
    kind : {"default", "shipped", "registered"}
    frame : {"canonical", "rig", "per rig"}
        "canonical": any rig with limb roles; "rig": only ``rig_family``'s skeleton; "per
        rig": the default choice, which picks per take.
    rig_family : str
        The rig a per-rig model covers (``"canonical"`` for a canonical model, ``""`` for the
        default choice).
    n_takes, n_frames : int
        Size of the build corpus (0 for the default choice).
    """

    name: str
    kind: str
    frame: str
    rig_family: str
    n_takes: int
    n_frames: int

    def to_json(self) -> dict[str, Any]:
        """The entry as a JSON-ready dict."""
        return {
            "name": self.name,
            "kind": self.kind,
            "frame": self.frame,
            "rig_family": self.rig_family,
            "n_takes": self.n_takes,
            "n_frames": self.n_frames,
        }


def check_model_name(name: object) -> str:
    """``name`` if it is a well-formed model name, else an OptionError naming ``limits_model``."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise OptionError(
            "limits_model",
            f"Expected a model name matching {MODEL_NAME_PATTERN} (lower-case letters, digits, "
            f"'_', '-'), got {name!r}",
        )
    return name


@functools.lru_cache(maxsize=32)
def _load_file(path: str, mtime_ns: int, size: int) -> LimitsModel:
    # Keyed by modification time and size, so a model registered again under the same name
    # is read anew; the shipped files never change while the process runs.
    from mocapqa.limits.storage import load_model

    del mtime_ns, size
    return load_model(path)


def _load_path(path: Path) -> LimitsModel:
    stat = path.stat()
    return _load_file(str(path), stat.st_mtime_ns, stat.st_size)


def _entry(name: str, kind: str, model: LimitsModel) -> ModelEntry:
    return ModelEntry(
        name=name,
        kind=kind,
        frame=model.frame,
        rig_family=model.rig_family,
        n_takes=len(model.takes),
        n_frames=model.n_frames,
    )


class ModelCatalog:
    """The choosable limits models: the default choice, the shipped files, registered files.

    Parameters
    ----------
    folder : Path, optional
        Folder of registered models (``<data folder>/limits_models``); None offers only the
        default and shipped models.
    """

    def __init__(self, folder: Path | None = None) -> None:
        self.folder = folder

    @classmethod
    def of_data_folder(cls, data_dir: str | Path | None) -> ModelCatalog:
        """The catalog of a server's or batch's data folder (shipped models only for None)."""
        return cls(None if data_dir is None else Path(data_dir) / MODELS_FOLDER)

    def _shipped(self) -> dict[str, Path]:
        from mocapqa.limits.storage import default_model_paths

        return {path.stem: path for path in default_model_paths()}

    def _registered(self) -> dict[str, Path]:
        if self.folder is None or not self.folder.is_dir():
            return {}
        return {
            path.stem: path
            for path in sorted(self.folder.glob("*.npz"))
            if _NAME.match(path.stem) and path.stem != DEFAULT_MODEL
        }

    def _path(self, name: str) -> tuple[str, Path] | None:
        shipped = self._shipped()
        if name in shipped:
            return "shipped", shipped[name]
        registered = self._registered()
        if name in registered:
            return "registered", registered[name]
        return None

    def names(self) -> list[str]:
        """Every choosable name: the default, the shipped files, the registered files."""
        return [DEFAULT_MODEL, *self._shipped(), *self._registered()]

    def entries(self) -> list[ModelEntry]:
        """Every choosable model with what it covers (registered files that no longer read as
        a model are left out)."""
        found = [ModelEntry(DEFAULT_MODEL, "default", "per rig", "", 0, 0)]
        for kind, paths in (("shipped", self._shipped()), ("registered", self._registered())):
            for name, path in paths.items():
                try:
                    found.append(_entry(name, kind, _load_path(path)))
                except (LimitsFileError, OSError):
                    continue
        return found

    def require(self, name: object) -> str:
        """``name`` if it is a choosable model.

        Raises
        ------
        OptionError
            Field ``limits_model``: a malformed or unknown name (the known ones listed).
        """
        checked = check_model_name(name)
        if checked != DEFAULT_MODEL and self._path(checked) is None:
            raise self._unknown(checked)
        return checked

    def _unknown(self, name: str) -> OptionError:
        """The error for a well-formed ``name`` that is no model here, listing the known ones."""
        return OptionError(
            "limits_model",
            f"Expected one of the limits models {self.names()}, got {name!r}; build one "
            "with `mocapqa limits build` and register it with `mocapqa limits register`",
        )

    def load(
        self, name: str, skeleton: Skeleton, mapping: Mapping[str, str] | None = None
    ) -> LimitsModel:
        """The model ``name`` chooses for ``skeleton`` (whose roles ``mapping`` may name).

        Raises
        ------
        OptionError
            An unknown name.
        LimitsFileError
            The model does not cover this skeleton (a per-rig model of another rig, a skeleton
            without limb roles), or its file is corrupt.
        """
        from mocapqa.limits.model import check_rig
        from mocapqa.limits.storage import load_default_model

        checked = check_model_name(name)
        if checked == DEFAULT_MODEL:
            return load_default_model(skeleton, mapping)
        found = self._path(checked)  # one look: a file unregistered meanwhile is unknown here
        if found is None:
            raise self._unknown(checked)
        model = _load_path(found[1])
        check_rig(model, skeleton, mapping)
        return model

    def register(self, source: Path, name: str, replace: bool = False) -> ModelEntry:
        """Copy the model file ``source`` into the catalog's folder as ``name``.

        The file is read first (a corrupt or foreign file is refused) and written under a
        temporary name then renamed, so a run never reads half a file.

        Raises
        ------
        OptionError
            A malformed name, the default's name or a shipped model's.
        ConflictError
            ``name`` is registered already and ``replace`` is false.
        LimitsFileError
            ``source`` is not a limits model.
        """
        check_model_name(name)
        if name == DEFAULT_MODEL or name in self._shipped():
            taken = [DEFAULT_MODEL, *self._shipped()]
            raise OptionError("limits_model", f"Expected a name other than the shipped {taken}")
        if self.folder is None:
            raise OptionError("limits_model", "Expected a data folder to register models in")
        from mocapqa.limits.storage import load_model

        model = load_model(source)
        target = self.folder / f"{name}.npz"
        if target.exists() and not replace:
            raise ConflictError(
                f"A limits model named {name!r} is registered already ({target}); pass "
                "--replace to overwrite it"
            )
        self.folder.mkdir(parents=True, exist_ok=True)
        temporary = self.folder / f".{name}.{uuid.uuid4().hex[:8]}.tmp"
        shutil.copyfile(source, temporary)
        os.replace(temporary, target)
        return _entry(name, "registered", model)
