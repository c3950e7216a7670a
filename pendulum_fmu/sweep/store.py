"""The study's output folder: study.json, a part per chunk of each table, the lock, the cases
table read back.

A local path or any fsspec URL every worker can write to. A chunk is done when its cases part
exists: its worker writes the trajectories part first. What an interrupted run leaves of the
chunks it did not finish is removed, so only whole chunks stay.
"""

from __future__ import annotations

import contextlib
import json
import os
from dataclasses import dataclass
from pathlib import Path

from ..atomic_files import TEMPORARY_GLOB, replacing_on
from ..errors import CannotWrite, InvalidInput, PendulumFmuError

SUMMARIES = ("final_theta", "final_omega", "final_alpha", "max_abs_theta")
# There while a run writes the study (see Store.only_run); hidden, and never part of a table.
LOCK_FILE = ".sweep.lock"


class InUse(PendulumFmuError, OSError):
    """Another run holds the output folder; the message says which folder and what to do."""


@dataclass(frozen=True)
class Store:
    """Where a study's files go: an fsspec file system, the folder's path on it, the tables'
    format."""

    filesystem: object  # fsspec
    root: str
    format: str

    def part(self, table: str, index: int) -> str:
        return f"{self.root}/{table}/part-{index:06d}.{self.format}"

    def write_table(self, name: str, index: int, columns: dict, split: tuple = ()) -> int:
        """Write one part of a table; returns its size in bytes. split: float columns stored
        byte-stream-split, as smooth series compress best."""
        import pyarrow as pa

        arrays = {column: pa.array(values) for column, values in columns.items()}
        # Not nullable (no value is ever missing): the writer then has no definition levels to write.
        table = pa.table(list(arrays.values()), schema=pa.schema(
            [pa.field(column, array.type, nullable=False) for column, array in arrays.items()]))
        with replacing_on(self.filesystem, self.part(name, index)) as file:
            if self.format == "parquet":
                import pyarrow.parquet as pq

                # Measured on trajectories (benchmarks/scale.py): LZ4 after byte-stream-split is as
                # small as zstd level 1 (57 kB for a 3-s case) and writes in a quarter of the time;
                # dictionaries only where values repeat within a column (case numbers, status).
                pq.write_table(table, file, compression="lz4",
                               use_dictionary=[c for c in table.column_names if c not in split],
                               column_encoding={c: "BYTE_STREAM_SPLIT" for c in split})
            else:
                import pyarrow.csv

                pyarrow.csv.write_csv(table, file)  # shortest round-trip digits: reads back exact
            return file.tell()

    def parts(self, table: str) -> dict[int, str]:
        """{chunk index: path} of a table's parts."""
        pattern = f"{self.root}/{table}/part-*.{self.format}"
        return {int(Path(path).stem.split("-")[1]): path for path in self.filesystem.glob(pattern)}

    def done_chunks(self) -> set[int]:
        return set(self.parts("cases"))

    def remove(self, patterns) -> None:
        for pattern in patterns:
            for path in self.filesystem.glob(f"{self.root}/{pattern}"):
                with contextlib.suppress(FileNotFoundError):
                    self.filesystem.rm(path)

    def remove_unfinished(self) -> None:
        """What interrupted chunks leave: the temporaries of writes cut short (a killed worker, see
        atomic_files.py), and trajectory parts whose chunk did not get to write its cases part."""
        self.remove((TEMPORARY_GLOB, f"trajectories/{TEMPORARY_GLOB}", f"cases/{TEMPORARY_GLOB}"))
        done = self.done_chunks()
        for index, path in self.parts("trajectories").items():
            if index not in done:
                with contextlib.suppress(FileNotFoundError):
                    self.filesystem.rm(path)

    def prepare(self, definition: dict, resume: bool, chunk_cases: int, output_dir) -> int:
        """Write study.json with the cases per chunk (or check it, on resume, and keep the
        earlier run's chunks); returns the cases per chunk."""
        fs, manifest = self.filesystem, f"{self.root}/study.json"
        if resume and fs.exists(manifest):
            with fs.open(manifest, "r") as file:
                previous = json.load(file)
            differences = [key for key in definition if previous["study"].get(key) != definition[key]]
            if differences:
                raise InvalidInput(
                    f"{output_dir} holds a different study ({', '.join(differences)} differ); leave "
                    "out --resume to replace it, or choose another output directory")
            return previous["chunk_cases"]
        # A new study replaces whatever study was there.
        self.remove(("study.json", "sweep.png", "trajectories/part-*", "cases/part-*"))
        with replacing_on(fs, manifest) as file:
            file.write(json.dumps({"study": definition, "chunk_cases": chunk_cases}, indent=1).encode())
        return chunk_cases

    @contextlib.contextmanager
    def only_run(self, output_dir):
        """Two runs into one folder would replace each other's parts: the second is refused at
        once (InUse) while the first runs. A lock held on a local folder, which the operating
        system releases however the run ends, so a killed run leaves at most a file that locks
        nothing; on other file systems (object stores have no locks) keeping runs apart is the
        user's part."""
        from filelock import FileLock, Timeout
        from fsspec.implementations.local import LocalFileSystem

        if not isinstance(self.filesystem, LocalFileSystem):
            yield
            return
        path = Path(self.root) / LOCK_FILE
        lock = FileLock(path, timeout=0)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise CannotWrite(f"cannot write {output_dir}: the folder {error.filename} cannot be created "
                              f"({error.strerror}); choose another output directory") from None
        try:
            lock.acquire()
        except Timeout:
            raise InUse(f"output directory {output_dir} is in use by another run (it holds {path}); "
                        "wait for that run to end, or choose another output") from None
        except OSError as error:
            raise CannotWrite(f"cannot write {output_dir}: {error.strerror or error}; choose "
                              "another output directory") from None
        try:
            yield
        finally:
            # Removed while still held: a run that opened the file meanwhile finds it unlinked
            # when it gets the lock, and filelock has it start over on a new file.
            with contextlib.suppress(OSError):  # Windows keeps an open file
                os.unlink(path)
            lock.release()

    def read_cases(self, names: list[str]):
        """The cases table's values and summaries, as a pyarrow table."""
        import pyarrow as pa
        import pyarrow.dataset as ds

        types = {"case": pa.int64(), **{n: pa.float64() for n in (*names, *SUMMARIES)},
                 "status": pa.string(), "message": pa.string()}
        if self.format == "csv":
            import pyarrow.csv

            file_format = ds.CsvFileFormat(convert_options=pyarrow.csv.ConvertOptions(column_types=types))
        else:
            file_format = "parquet"
        dataset = ds.dataset(f"{self.root}/cases", format=file_format, schema=pa.schema(types),
                             filesystem=self.filesystem)
        return dataset.to_table(columns=["case", *names, "max_abs_theta", "final_theta", "status"])
