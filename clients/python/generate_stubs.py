#!/usr/bin/env python3
"""Regenerates the gRPC stubs in kinplan/v1 from ../../proto (needs grpcio-tools
and mypy-protobuf: pip install -e '.[dev]'). The stubs are committed so that
installing the package needs no code generation."""
import pathlib
import sys

from grpc_tools import protoc

HERE = pathlib.Path(__file__).resolve().parent
PROTO = HERE.parent.parent / "proto"


def main() -> int:
    files = sorted(str(p.relative_to(PROTO)) for p in (PROTO / "kinplan" / "v1").glob("*.proto"))
    include = pathlib.Path(protoc.__file__).parent / "_proto"
    args = [
        "protoc",
        f"-I{PROTO}",
        f"-I{include}",
        f"--python_out={HERE}",
        f"--pyi_out={HERE}",
        f"--grpc_python_out={HERE}",
        f"--plugin=protoc-gen-mypy_grpc={pathlib.Path(sys.executable).parent / 'protoc-gen-mypy_grpc'}",
        f"--mypy_grpc_out={HERE}",
        *files,
    ]
    code = protoc.main(args)
    (HERE / "kinplan" / "v1" / "__init__.py").write_text('"""Generated gRPC stubs (do not edit)."""\n')
    return code


if __name__ == "__main__":
    sys.exit(main())
