"""The study's output folder: study.json, a part per chunk of each table, the lock, the cases
table read back.

A local path or any fsspec URL every worker can write to. A chunk is done when its cases part
exists. What an interrupted run leaves of the chunks it did not finish is removed, so only whole
chunks stay.

Writes are fenced: each run of a study has a token of its own (study.json's "run"), which every
task carries. A worker writes a chunk's parts under staged names that hold the token
(_part-000006.<run>.staged: hidden from pyarrow's, pandas' and dask's readers, and matching no
*.parquet glob); only the run's client, which holds the folder, renames its own run's staged
parts into place (part-000006.parquet), the trajectories first. So a part written by a worker
of another run (one stopped, then continued after its study was finished, replaced or resumed)
never becomes part of a study, and every reader, resume included, lists only parts a client
committed. A run removes the staged parts it finds, of any run, when it ends.

Nor does such a worker leave its parts behind. A run marks itself live (.live-<run>) while it
runs, and ends by removing the mark, then the staged parts it finds. A worker checks its run's mark
after it has staged its parts, and removes them when the mark is gone. Either the check comes
before the mark goes, and the parts, staged before it, are there when the run removes what it
finds; or it comes after, and the worker removes them itself. A worker never makes a folder
either: a study written apart (overwrite) is moved into place when its run ends, and a worker
of that run, woken later, finds no folder to stage into and writes nothing.

A study that a run replaces (overwrite) stays whole until the new one is: the new study is
written into a hidden folder inside the output folder and moved into place at the end, with
Ctrl-C held off while it moves.
"""

from __future__ import annotations

import contextlib
import json
import os
import uuid
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._atomic_files import TEMPORARY_GLOB, is_local, make_folder, replacing_on
from .._errors import CannotWrite, InvalidInput, PendulumFmuError
from .._received_files import MAX_STUDY_BYTES, bounded_read
from .._stop_signals import signals_deferred

SUMMARIES = ("final_theta", "final_omega", "final_alpha", "max_abs_theta")
# What a study is made of in its folder: study.json first, so that what a study holds is known
# before any part of it is written.
ENTRIES = ("study.json", "trajectories", "cases", "sweep.png")
# There while a run writes the study (see Store.only_run); hidden, and never part of a table.
LOCK_FILE = ".sweep.lock"
# What a worker writes and only its run's client moves into place (see the module's doc).
STAGED_GLOB = "_part-*.staged"
# What to do with a study.json too long to be one a sweep wrote.
_STUDY_ADVICE = "choose another output directory, or add --overwrite to replace what it holds"
# There while a run is writing the study, one per run (.live-<run>): see Store.is_live.
LIVE_GLOB = ".live-*"


def parquet_options(columns: list[str], series: tuple = ()) -> dict:
    """pyarrow.parquet.write_table's options for a part with these columns, of which series are
    float series over the time grid (see Store.write_table).

    Measured on trajectories (python -m benchmarks.chunk_cost, docs/sweep_performance.md): LZ4
    after byte-stream-split is within 2 % of zstd's size (57 kB for a 3-s case) for little more
    than half its CPU, and 23 % smaller than LZ4 alone. A series spans its whole range in every
    part, so its min/max statistics would let no reader skip a part: only the other columns
    (case numbers, a case's values) have them. Dictionaries in the cases table, whose values
    repeat (status, the swept values); a trajectories part's case numbers, runs of one value,
    cost less plain under LZ4 (10 % fewer instructions for the part, 0.006 ms per 3-s case, 0.2 %
    larger). Batches of 65,536 values rather than pyarrow's 1,024: fewer passes through the
    writer per page.
    """
    return {
        "compression": "lz4",
        "use_dictionary": not series,
        "column_encoding": {column: "BYTE_STREAM_SPLIT" for column in series} or None,
        "write_statistics": [column for column in columns if column not in series],
        "write_batch_size": 65536,
    }


class InUse(PendulumFmuError, OSError):
    """Another run holds the output folder; the message says which folder and what to do."""


class StudyExists(PendulumFmuError, FileExistsError):
    """The output folder holds a study (or what looks like one) that the run would replace
    without being asked to; the message says what it holds, and names --resume and --overwrite.
    """


@dataclass(frozen=True)
class Held:
    """What an output folder holds: its study.json's content (None when there is none that a
    sweep wrote), the study's entries present, and the chunks done.
    """

    manifest: dict | None
    entries: tuple[str, ...]
    done_chunks: int

    def chunks(self) -> int:
        """The chunks of the study the folder holds (its study.json's cases and cases per chunk)."""
        if self.manifest is None:
            raise ValueError("the folder holds no study.json of a sweep: it has no chunks")
        return -(-self.manifest["study"]["cases"] // self.manifest["chunk_cases"])


@dataclass(frozen=True)
class Store:
    """Where a study's files go: an fsspec file system, the folder's path on it, the tables'
    format.
    """

    filesystem: Any  # an fsspec AbstractFileSystem (fsspec ships no types), or LocalFolders
    root: str
    format: str

    def dataset_filesystem(self):
        """The file system to give pyarrow's dataset: its own for a local folder (it takes no
        LocalFolders), the store's elsewhere.
        """
        return None if is_local(self.filesystem) else self.filesystem

    def part(self, table: str, index: int) -> str:
        """The path of a table's part for a chunk."""
        return f"{self.root}/{table}/part-{index:06d}.{self.format}"

    def staged(self, table: str, index: int, run: str) -> str:
        """Where a worker of run writes a chunk's part, for the run's client to commit."""
        return f"{self.root}/{table}/_part-{index:06d}.{run}.staged"

    def write_table(self, name: str, index: int, columns: dict, run: str, series: tuple = ()) -> int:
        """Write one part of a table, staged for run (see commit); returns its size in bytes.
        series: the columns that are float series over the time grid (a trajectories part's time
        and outputs), stored as parquet_options says. FileNotFoundError where the table's folder
        is not there (start makes it): no folder is made after the run's start.
        """
        import pyarrow as pa

        arrays = {column: pa.array(values) for column, values in columns.items()}
        # Not nullable (no value is ever missing): the writer then has no definition levels to write.
        table = pa.table(
            list(arrays.values()),
            schema=pa.schema([pa.field(column, array.type, nullable=False) for column, array in arrays.items()]),
        )
        with replacing_on(self.filesystem, self.staged(name, index, run), make_folders=False) as file:
            if self.format == "parquet":
                import pyarrow.parquet as pq

                pq.write_table(table, file, **parquet_options(table.column_names, series))
            else:
                import pyarrow.csv

                pyarrow.csv.write_csv(table, file)  # shortest round-trip digits: reads back exact
            return file.tell()

    def commit(self, index: int, run: str, tables: tuple[str, ...]) -> None:
        """Move run's staged parts of a chunk into place: the chunk is then done. Only the parts
        staged under this run's token: a part another run staged stays out of the study.
        """
        for table in tables:  # the cases part last: it marks the chunk done
            self.filesystem.mv(self.staged(table, index, run), self.part(table, index))

    def live(self, run: str) -> str:
        """The path of run's mark: there from the run's start until it ends."""
        return f"{self.root}/.live-{run}"

    def is_live(self, run: str) -> bool:
        """Whether run is still writing this study (see the module's doc)."""
        return self.filesystem.exists(self.live(run))

    def discard_staged(self, index: int, run: str, tables: tuple[str, ...]) -> None:
        """Remove run's staged parts of a chunk, where they are."""
        for table in tables:
            with contextlib.suppress(FileNotFoundError):
                self.filesystem.rm(self.staged(table, index, run))

    def parts(self, table: str) -> dict[int, str]:
        """{chunk index: path} of a table's parts."""
        pattern = f"{self.root}/{table}/part-*.{self.format}"
        return {int(Path(path).stem.split("-")[1]): path for path in self.filesystem.glob(pattern)}

    def done_chunks(self) -> set[int]:
        """The indices of the chunks whose cases are written."""
        return set(self.parts("cases"))

    def remove(self, patterns: Iterable[str]) -> None:
        """Remove every file or folder under the root that the glob patterns match."""
        for pattern in patterns:
            for path in self.filesystem.glob(f"{self.root}/{pattern}"):
                with contextlib.suppress(FileNotFoundError):
                    self.filesystem.rm(path, recursive=True)

    def remove_unfinished(self) -> None:
        """End every run of the folder: their marks first (see the module's doc), then what
        interrupted chunks leave: the temporaries of writes cut short (a killed worker, see
        _atomic_files.py), the staged parts no client committed (of this run or any other), and
        trajectory parts whose chunk did not get to commit its cases part.
        """
        self.remove((LIVE_GLOB,))
        self.remove(
            (
                TEMPORARY_GLOB,
                *(
                    f"{table}/{pattern}"
                    for table in ("trajectories", "cases")
                    for pattern in (TEMPORARY_GLOB, STAGED_GLOB)
                ),
            )
        )
        done = self.done_chunks()
        for index, path in self.parts("trajectories").items():
            if index not in done:
                with contextlib.suppress(FileNotFoundError):
                    self.filesystem.rm(path)

    def held(self) -> Held:
        """What the folder holds of a study."""
        fs, manifest, path = self.filesystem, None, f"{self.root}/study.json"
        try:
            with fs.open(path, "rb") as file:
                raw = bounded_read(file, path, MAX_STUDY_BYTES, InvalidInput, _STUDY_ADVICE)
        except OSError:  # none there
            raw = b"{}"
        # Not JSON, or JSON nested deeper than the decoder recurses: no study.json a sweep wrote.
        with contextlib.suppress(ValueError, RecursionError):
            content = json.loads(raw)
            if (
                isinstance(content, dict)
                and isinstance(content.get("study"), dict)
                and isinstance(content.get("chunk_cases"), int)
            ):
                manifest = content
        entries = tuple(name for name in ENTRIES if fs.exists(f"{self.root}/{name}"))
        return Held(manifest, entries, len(self.done_chunks()) if entries else 0)

    def start(self, definition: dict, chunk_cases: int, run: str, tables: tuple[str, ...]) -> None:
        """Write study.json: what the study is, its cases per chunk, and the token of the run
        now writing it; make the folders of the tables' parts, and mark the run live.
        """
        with replacing_on(self.filesystem, f"{self.root}/study.json") as file:
            # One line: json's C encoder (indent= takes its Python one, 0.2 s for 50,000 values).
            file.write(json.dumps({"study": definition, "chunk_cases": chunk_cases, "run": run}).encode())
        if is_local(self.filesystem):  # elsewhere a file's path makes its folders, if it has any
            for table in tables:
                make_folder(Path(self.root, table), self.root, "output directory")
        with replacing_on(self.filesystem, self.live(run)):
            pass

    def staging(self) -> Store:
        """A new hidden folder inside this one, where a study that replaces this one is written."""
        return Store(self.filesystem, f"{self.root}/.overwrite.{uuid.uuid4().hex}.partial", self.format)

    def replace_with(self, staged: Store) -> None:
        """Move the staged study into this folder in place of the one it holds, which goes. Ctrl-C
        and SIGTERM wait until the move is done, so they find the old study or the new one; the
        old study.json goes first and the new one comes last, so that even a killed move leaves
        no study.json over a mix of the two.
        """
        fs = self.filesystem
        aside = f"{self.root}/.replaced.{uuid.uuid4().hex}.partial"
        with signals_deferred():
            fs.makedirs(aside, exist_ok=True)
            for name in ENTRIES:
                if fs.exists(f"{self.root}/{name}"):
                    fs.mv(f"{self.root}/{name}", f"{aside}/{name}", recursive=True)
            for name in (*ENTRIES[1:], ENTRIES[0]):
                if fs.exists(f"{staged.root}/{name}"):
                    fs.mv(f"{staged.root}/{name}", f"{self.root}/{name}", recursive=True)
            for folder in (aside, staged.root):
                with contextlib.suppress(FileNotFoundError):
                    fs.rm(folder, recursive=True)

    def discard(self) -> None:
        """Remove this folder and everything in it (a staged study that did not finish)."""
        with contextlib.suppress(FileNotFoundError):
            self.filesystem.rm(self.root, recursive=True)

    @contextlib.contextmanager
    def only_run(self, output_dir):
        """Two runs into one folder would replace each other's parts: the second is refused at
        once (InUse) while the first runs. A lock held on a local folder, which the operating
        system releases however the run ends, so a killed run leaves at most a file that locks
        nothing; on other file systems (object stores have no locks) keeping runs apart is the
        user's part.
        """
        from filelock import FileLock, Timeout

        if not is_local(self.filesystem):
            yield
            return
        path = Path(self.root) / LOCK_FILE
        lock = FileLock(path, timeout=0)
        make_folder(path.parent, output_dir, "output directory")
        try:
            lock.acquire()
        except Timeout:
            raise InUse(
                f"output directory {output_dir} is in use by another run (it holds {path}); "
                "wait for that run to end, or choose another output"
            ) from None
        except OSError as error:
            raise CannotWrite(
                f"cannot write {output_dir}: {error.strerror or error}; choose another output directory"
            ) from None
        try:
            yield
        finally:
            # Removed while still held: a run that opened the file meanwhile finds it unlinked
            # when it gets the lock, and filelock has it start over on a new file.
            with contextlib.suppress(OSError):  # Windows keeps an open file
                os.unlink(path)
            lock.release()

    def read_cases(self, names: list[str]):
        """The cases table's values and summaries, as a pyarrow table, its parts in the order of
        their paths (as pyarrow's dataset lists them).
        """
        import pyarrow as pa

        types = {
            "case": pa.int64(),
            **{n: pa.float64() for n in (*names, *SUMMARIES)},
            "status": pa.string(),
            "message": pa.string(),
        }
        columns = ["case", *names, "max_abs_theta", "final_theta", "status"]
        if self.format == "csv":
            import pyarrow.csv
            import pyarrow.dataset as ds

            dataset = ds.dataset(
                f"{self.root}/cases",
                format=ds.CsvFileFormat(convert_options=pyarrow.csv.ConvertOptions(column_types=types)),
                schema=pa.schema(types),
                filesystem=self.dataset_filesystem(),
            )
            return dataset.to_table(columns=columns)
        # Part by part, not through pyarrow.dataset, whose import (with pyarrow.compute's, ~35 ms)
        # was a tenth of a small study's time in the process.
        import pyarrow.parquet as pq

        selected = pa.schema([pa.field(column, types[column]) for column in columns])
        tables = [selected.empty_table()]
        for path in sorted(self.parts("cases").values()):
            with self.filesystem.open(path, "rb") as file:
                part = pq.ParquetFile(file).read(columns=columns)
            # Given the schema, not cast: a cast imports pyarrow.compute even where only the
            # fields' nullable flags differ, as they do; a column of another type (int32 case
            # numbers, numpy 1 on Windows) is cast all the same.
            tables.append(pa.Table.from_arrays(part.columns, schema=selected))
        return pa.concat_tables(tables)
