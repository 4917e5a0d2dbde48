"""The one way Python binds the native library (`mbsuite.engines.native.bind`): a declaration whose ABI or struct
size disagrees with the C is refused with both values, concurrent loads give one handle and one binding, and the
library's sources (and its cache key) cover the shared components' `native/` folders."""

from __future__ import annotations

import ctypes
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from mbsuite.engines import native
from mbsuite.engines.native import binding
from mbsuite.models.catenary import native_core

CAT = "models/catenary/native/catenary.c"


def _declaration(**kw) -> native.Declaration:
    d = {"source": CAT, "abi_function": "mbs_cat_abi", "abi": native_core.ABI,
         "functions": (native.CFunction("mbs_cat_solve", None, (ctypes.c_void_p, ctypes.c_void_p)),),
         "structs": (native.CStruct(native_core._Job, "mbs_cat_job_size"),)}
    return native.Declaration(**{**d, **kw})


def test_catenary_binding_is_cached_and_declares_its_functions():
    lib = native_core.library()
    assert lib is native_core.library() is native.bind(native_core.DECLARATION)
    assert lib.mbs_cat_run.argtypes == [ctypes.c_void_p, ctypes.c_long, ctypes.c_long, ctypes.c_int]
    assert lib.mbs_cat_job_size() == ctypes.sizeof(native_core._Job)
    with pytest.raises(AttributeError, match="mbs_cat_nothing is not declared"):
        _ = lib.mbs_cat_nothing


def test_a_struct_size_mismatch_is_refused_naming_both_sizes():
    class Longer(native_core._Job):
        _fields_ = [("extra", ctypes.c_double)]

    c_size = ctypes.sizeof(native_core._Job)
    with pytest.raises(native.NativeBuildError) as err:
        native.bind(_declaration(structs=(native.CStruct(Longer, "mbs_cat_job_size"),)))
    text = str(err.value)
    assert CAT in text and "mbs_cat_job_size()" in text and "Longer" in text
    assert f"returns {c_size} bytes" in text and f"is {c_size + 8} bytes" in text


def test_an_abi_mismatch_is_refused_naming_both_versions():
    wrong = native_core.ABI + 1
    with pytest.raises(native.NativeBuildError) as err:
        native.bind(_declaration(abi=wrong))
    text = str(err.value)
    assert CAT in text and "mbs_cat_abi()" in text
    assert f"returns ABI {native_core.ABI}" in text and f"expects ABI {wrong}" in text


def test_a_missing_function_or_a_foreign_source_is_refused():
    with pytest.raises(native.NativeBuildError, match=f"{CAT} .*has no function mbs_cat_nothing"):
        native.bind(_declaration(functions=(native.CFunction("mbs_cat_nothing", ctypes.c_int),)))
    with pytest.raises(native.NativeBuildError, match="models/nothing/native/x.c is not a source"):
        native.bind(_declaration(source="models/nothing/native/x.c"))


def test_two_declarations_keep_their_own_argtypes():
    """Each binding owns its function objects: declaring a function again elsewhere leaves the others untouched."""
    other = native.bind(_declaration(functions=(native.CFunction("mbs_cat_solve", ctypes.c_int, (ctypes.c_char_p,)),)))
    assert other.mbs_cat_solve.argtypes == [ctypes.c_char_p]
    assert native_core.library().mbs_cat_solve.argtypes == [ctypes.c_void_p, ctypes.c_void_p]
    assert native_core.library().mbs_cat_solve.restype is None


def test_binding_from_threads_at_once_declares_once(monkeypatch):
    """Eight threads bind a new declaration at the same instant, with a slow declare: one declare, one binding."""

    class Same(native_core._Job):  # a new struct class: a declaration no other test has bound
        pass

    decl = _declaration(structs=(native.CStruct(Same, "mbs_cat_job_size"),))
    calls = []
    real = binding.declare

    def slow(*args):
        calls.append(1)
        time.sleep(0.05)
        return real(*args)

    monkeypatch.setattr(binding, "declare", slow)
    start = threading.Barrier(8)
    got: list[native.Binding] = []

    def worker() -> None:
        start.wait()
        got.append(native.bind(decl))

    threads = [threading.Thread(target=worker) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(got) == 8 and all(b is got[0] for b in got)
    assert len(calls) == 1


def test_loading_from_threads_at_once_in_a_fresh_process_gives_one_handle():
    code = textwrap.dedent("""
        import threading
        from mbsuite.engines import native
        from mbsuite.models.catenary import native_core
        start, handles, bindings = threading.Barrier(6), [], []
        def worker(i):
            start.wait()
            (handles.append(native.load()) if i % 2 else bindings.append(native_core.library()))
        threads = [threading.Thread(target=worker, args=(i,)) for i in range(6)]
        for t in threads: t.start()
        for t in threads: t.join()
        assert len(handles) == 3 and all(h is handles[0] for h in handles), handles
        assert len(bindings) == 3 and all(b is bindings[0] for b in bindings), bindings
        assert bindings[0].handle is handles[0]
        print("ok")
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr


def test_sources_cover_component_native_folders_and_the_key_their_content(monkeypatch, tmp_path: Path):
    """An empty components glob changes nothing; component C files come last, sorted, and the cache key follows every
    byte of them and of their headers."""
    empty = tmp_path / "none"
    monkeypatch.setattr(native, "COMPONENTS_DIR", empty)
    base, base_headers, base_key = native.sources(), native._headers(), native.build_key()
    comp = tmp_path / "components"
    for rel in ("spring/native/b.c", "spring/native/a.c", "brake/native/z.c", "brake/native/z.h"):
        (comp / rel).parent.mkdir(parents=True, exist_ok=True)
        (comp / rel).write_text("/* one */\n")
    monkeypatch.setattr(native, "COMPONENTS_DIR", comp)
    assert native.sources() == base + [comp / "brake/native/z.c", comp / "spring/native/a.c",
                                       comp / "spring/native/b.c"]
    assert native._headers() == base_headers + [comp / "brake/native/z.h"]
    keys = {base_key, native.build_key()}
    (comp / "spring/native/a.c").write_text("/* two */\n")
    keys.add(native.build_key())
    (comp / "brake/native/z.h").write_text("/* two */\n")
    keys.add(native.build_key())
    assert len(keys) == 4
