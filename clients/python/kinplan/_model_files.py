"""A URDF and the collision mesh files it names, read on the client: the
server never opens a file, so the bytes travel with the model (once; the
model id the server returns names both afterwards).

Mesh URIs are resolved the way pinocchio's ``buildGeomFromUrdf(model, path,
COLLISION, package_dirs)`` does: ``package://pkg/rest`` is looked for as
``dir/pkg/rest`` (then ``dir/rest``) under each of `package_dirs`, a
relative path next to the URDF file (then under each package dir), and
``file://`` or absolute paths as they are."""

import os
import pathlib
import xml.etree.ElementTree as ElementTree
from typing import Dict, List, Mapping, Optional, Sequence, Tuple, Union

from .errors import invalid_argument

PathLike = Union[str, "os.PathLike[str]"]


def _looks_like_path(urdf: PathLike) -> bool:
    return isinstance(urdf, os.PathLike) or ("<" not in urdf and urdf.strip().lower().endswith((".urdf", ".xml")))


def load_text(doc: Optional[PathLike], field: str) -> Optional[str]:
    """A document given as text or as an existing file's path (``None`` stays ``None``)."""
    if doc is None:
        return None
    if isinstance(doc, os.PathLike) or ("<" not in doc and doc.strip().lower().endswith((".srdf", ".xml", ".urdf"))):
        path = pathlib.Path(doc)
        if not path.is_file():
            raise invalid_argument(field, f"{str(doc)!r} looks like a file path, but no such file exists here")
        return path.read_text(encoding="utf-8")
    return str(doc)


def collision_mesh_uris(urdf_text: str) -> List[str]:
    """The ``<mesh filename>`` of every ``<collision>`` element, in order, once each."""
    try:
        root = ElementTree.fromstring(urdf_text)
    except ElementTree.ParseError:
        return []  # the server names what is wrong with the document
    seen: Dict[str, None] = {}
    for collision in root.iter("collision"):
        for mesh in collision.iter("mesh"):
            uri = mesh.get("filename")
            if uri:
                seen.setdefault(uri, None)
    return list(seen)


def _candidates(uri: str, base: Optional[pathlib.Path], package_dirs: Sequence[PathLike]) -> List[pathlib.Path]:
    dirs = [pathlib.Path(d) for d in package_dirs]
    if uri.startswith("package://"):
        rest = uri[len("package://"):]
        package, _, inside = rest.partition("/")
        return [p for d in dirs for p in (d / package / inside, d / inside)]
    if uri.startswith("file://"):
        return [pathlib.Path(uri[len("file://"):])]
    path = pathlib.Path(uri)
    if path.is_absolute():
        return [path]
    return ([base / path] if base is not None else []) + [d / path for d in dirs]


def load_model(
    urdf: PathLike,
    package_dirs: Optional[Sequence[PathLike]] = None,
    meshes: Optional[Mapping[str, bytes]] = None,
) -> Tuple[str, Dict[str, bytes]]:
    """The URDF text (`urdf` is the text, or the path of an existing file)
    and its collision mesh files as ``{uri: bytes}``: those given in
    `meshes`, and every other one found on disk. Files are looked for only
    when the URDF came from a file or `package_dirs` are given; then a mesh
    that cannot be found raises :class:`FileNotFoundError` naming its URI and
    every place looked. Without either, only `meshes` are sent (FK and IK
    need none; collision calls name a missing file)."""
    base: Optional[pathlib.Path] = None
    if _looks_like_path(urdf):
        path = pathlib.Path(urdf)
        if not path.is_file():
            raise invalid_argument(
                "urdf",
                f"{str(urdf)!r} looks like a file path, but no such file exists here; urdf= takes an existing "
                "file's path or the document's text (urdf=open(path).read())",
            )
        text = path.read_text(encoding="utf-8")
        base = path.resolve().parent
    else:
        text = str(urdf)
    files: Dict[str, bytes] = dict(meshes or {})
    if base is None and package_dirs is None:
        return text, files
    for uri in collision_mesh_uris(text):
        if uri in files:
            continue
        places = _candidates(uri, base, package_dirs or [])
        found = next((p for p in places if p.is_file()), None)
        if found is None:
            looked = ", ".join(str(p) for p in places) or "nowhere (give package_dirs=[...])"
            raise FileNotFoundError(f"mesh {uri!r} named by the URDF was not found; looked in: {looked}")
        files[uri] = found.read_bytes()
    return text, files
