"""Who can drive a sweep's workers: another process against the local cluster (refused), a TLS
cluster on the loopback with certificates made here (reached with the --tls-* options, with
dask's configuration, refused with a wrong CA, in one line), the warning for a plain tcp://
scheduler off the loopback, and what no run owns cleared from a study's folder.
"""

import datetime
import json
import logging
import os
import subprocess
import sys
import textwrap

import numpy as np
import pyarrow.parquet as pq
import pytest
from dask.distributed import LocalCluster
from distributed.security import Security

from pendulum_fmu.cli import main
from pendulum_fmu.sweep import Study, run_sweep, sweep_grid, tls_files
from pendulum_fmu.sweep.client import SchedulerUnreachable, dask_client
from pendulum_fmu.sweep.security import _on_loopback
from pendulum_fmu.sweep.store import Store

# Every test here starts a dask cluster of processes, or a scheduler and workers of its own.
pytestmark = pytest.mark.cluster

I_TOTAL = 20.0 + 40.0 * 0.5**2  # the tutorial's pendulum about its pivot
STOP_TIME = 0.2


@pytest.fixture(autouse=True)
def _built_fmu(fmu, monkeypatch):
    """Every study here runs the FMU built for this session."""
    monkeypatch.setattr("pendulum_fmu.default_fmu", lambda: fmu)


def _key_and_certificate(name: str, issuer=None) -> tuple:
    """(key, certificate) for name, signed by issuer's (key, certificate), or self-signed as a CA."""
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import NameOID

    key = ec.generate_private_key(ec.SECP256R1())
    subject = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, name)])
    signer_key, signer = issuer if issuer else (key, None)
    now = datetime.datetime.now(datetime.UTC)
    certificate = (
        x509.CertificateBuilder()
        .subject_name(subject)
        .issuer_name(signer.subject if signer else subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=1))
        .add_extension(x509.BasicConstraints(ca=issuer is None, path_length=None), critical=True)
        .sign(signer_key, hashes.SHA256())
    )
    return key, certificate


def _write(folder, name: str, key, certificate) -> tuple[str, str]:
    """The PEM files name.key and name.pem in folder: (certificate's path, key's path)."""
    from cryptography.hazmat.primitives import serialization

    (folder / f"{name}.key").write_bytes(
        key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption())
    )
    (folder / f"{name}.pem").write_bytes(certificate.public_bytes(serialization.Encoding.PEM))
    return str(folder / f"{name}.pem"), str(folder / f"{name}.key")


@pytest.fixture(scope="module")
def certificates(tmp_path_factory) -> dict[str, tuple[str, str]]:
    """{name: (certificate, key)}: the cluster's CA ("ca"), the scheduler's and workers' ("node")
    and a client's ("client") it signed; another CA ("stranger-ca") and a client it signed
    ("stranger").
    """
    folder = tmp_path_factory.mktemp("certificates")
    authority, stranger_authority = _key_and_certificate("study CA"), _key_and_certificate("another CA")
    return {
        "ca": _write(folder, "ca", *authority),
        "node": _write(folder, "node", *_key_and_certificate("node", authority)),
        "client": _write(folder, "client", *_key_and_certificate("client", authority)),
        "stranger-ca": _write(folder, "stranger-ca", *stranger_authority),
        "stranger": _write(folder, "stranger", *_key_and_certificate("stranger", stranger_authority)),
    }


@pytest.fixture(scope="module")
def tls_scheduler(certificates):
    """The address of a TLS scheduler on the loopback with a worker (threads of this process),
    both with the node's certificate; only a client whose certificate the CA signed gets in.
    """
    (ca, _), (cert, key) = certificates["ca"], certificates["node"]
    node = {
        f"tls_{role}_{kind}": path
        for role in ("scheduler", "worker", "client")
        for kind, path in (("cert", cert), ("key", key))
    }
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tls://",
        security=Security(require_encryption=True, tls_ca_file=ca, **node),
        dashboard_address="127.0.0.1:0",
        silence_logs=logging.CRITICAL,
    ) as cluster:
        yield cluster.scheduler_address


def _tls_options(certificates, ca="ca", client="client") -> list[str]:
    return [
        "--tls-ca-file",
        certificates[ca][0],
        "--tls-cert",
        certificates[client][0],
        "--tls-key",
        certificates[client][1],
    ]


def _sweep(output_dir, *options) -> list[str]:
    return [
        "sweep",
        "--torque",
        "2",
        "4",
        "--gravity",
        "0",
        "--stop-time",
        str(STOP_TIME),
        "--output-dir",
        str(output_dir),
        *options,
    ]


def _assert_the_study(output_dir) -> None:
    """The two cases of _sweep, against theta = tau t^2 / (2 I) (no gravity)."""
    table = pq.read_table(output_dir / "cases").sort_by("case")
    assert table["torque"].to_pylist() == [2.0, 4.0] and table["status"].to_pylist() == ["ok", "ok"]
    expected = 0.5 * np.array([2.0, 4.0]) / I_TOTAL * STOP_TIME**2
    assert np.max(np.abs(table["final_theta"].to_numpy() - expected)) < 1e-12


# --- the local cluster: only the run's client gets in --------------------------------------

# Another process of the machine, as in issue 38: a client on each of the cluster's addresses,
# over plain TCP, over TLS without certificates, over TLS with certificates of its own; each that
# connects runs code on every worker (a file written). All at once, 12 s in all: one that
# never answers (a plain TCP client waits for a TLS server's handshake, and it for the client's)
# is refused as much as one turned away.
ATTACK = textwrap.dedent(
    """
    import json, os, sys, threading, time
    from dask.distributed import Client
    from distributed.security import Security

    addresses, marker = json.loads(sys.argv[1]), sys.argv[2]
    own, outcomes = Security.temporary(), {}

    def attack(label, address, security):
        try:
            client = Client(address, timeout=5, security=security)
        except Exception as error:
            outcomes[label] = "refused: " + type(error).__name__
            return
        client.run(lambda: open(marker, "a").write("ran\\n"))
        outcomes[label] = "ran"

    attempts = []
    for address in addresses:
        port = address.rsplit(":", 1)[1]
        for label, url, security in (
            ("tcp", "tcp://127.0.0.1:" + port, None),
            ("tls", "tls://127.0.0.1:" + port, None),
            ("tls, own certificates", "tls://127.0.0.1:" + port, own),
        ):
            attempt = threading.Thread(target=attack, args=(label + " " + port, url, security), daemon=True)
            attempt.start()
            attempts.append((label + " " + port, attempt))
    deadline = time.monotonic() + 12
    for label, attempt in attempts:
        attempt.join(max(0.0, deadline - time.monotonic()))
        outcomes.setdefault(label, "no answer")
    print(json.dumps(outcomes), flush=True)
    os._exit(0)  # not waiting for the clients still waiting on a handshake
    """
)


def test_another_process_cannot_run_code_on_the_local_cluster(tmp_path):
    marker = tmp_path / "ran.txt"
    with dask_client(None, 1, 30.0) as client:
        info = client.scheduler_info()
        workers = list(info["workers"])
        nannies = [worker["nanny"] for worker in info["workers"].values()]
        addresses = [client.scheduler.address, *workers, *nannies]
        assert all(address.startswith("tls://127.0.0.1:") for address in addresses), addresses
        # The run's own client reaches every worker.
        assert len(client.run(os.getpid)) == 1
        attack = subprocess.run(
            [sys.executable, "-c", ATTACK, json.dumps(addresses), str(marker)],
            capture_output=True,
            text=True,
            timeout=180,
        )
        outcomes = json.loads(attack.stdout.splitlines()[-1])
        assert len(outcomes) == 3 * len(addresses)
        assert not [label for label, outcome in outcomes.items() if outcome == "ran"], outcomes
        assert not marker.exists()
        assert len(client.run(os.getpid)) == 1  # and the cluster still works for its run


def test_the_local_cluster_s_pages_are_on_the_loopback():
    with dask_client(None, 1, 30.0) as client:
        assert client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.http_server.address) == "127.0.0.1"


# --- a TLS cluster reached with dask's settings ----------------------------------------------


def test_a_sweep_on_a_tls_scheduler_with_the_tls_options(tmp_path, tls_scheduler, certificates, capsys):
    assert main(_sweep(tmp_path, "--scheduler", tls_scheduler, *_tls_options(certificates))) == 0
    assert "2 cases" in capsys.readouterr().out
    _assert_the_study(tmp_path)


def test_a_sweep_on_a_tls_scheduler_with_dask_s_configuration(tmp_path, tls_scheduler, certificates, fmu):
    (ca, _), (cert, key) = certificates["ca"], certificates["client"]
    environment = {
        **os.environ,
        "DASK_DISTRIBUTED__COMM__TLS__CA_FILE": ca,
        "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT": cert,
        "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY": key,
    }
    command = [sys.executable, "-m", "pendulum_fmu", *_sweep(tmp_path, "--scheduler", tls_scheduler, "--fmu", str(fmu))]
    done = subprocess.run(command, env=environment, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "2 cases" in done.stdout, done.stderr
    _assert_the_study(tmp_path)


def test_a_sweep_on_a_tls_scheduler_through_the_python_api(tmp_path, tls_scheduler, certificates):
    security = tls_files(certificates["ca"][0], *certificates["client"])
    result = run_sweep(
        Study(sweep_grid([2.0, 4.0], [0.0]), stop_time=STOP_TIME),
        output_dir=tmp_path,
        scheduler=tls_scheduler,
        security=security,
        progress=False,
    )
    assert (result.cases, result.failed) == (2, 0)
    _assert_the_study(tmp_path)


@pytest.mark.parametrize(
    "ca, client, said",
    [
        # The scheduler's certificate is not signed by the CA given: the client refuses it.
        ("stranger-ca", "client", "the TLS handshake failed"),
        # The client's certificate is not signed by the scheduler's CA: the scheduler refuses it.
        ("ca", "stranger", "the TLS handshake failed"),
    ],
)
def test_a_tls_scheduler_refused_by_certificates_is_one_line(
    tmp_path, tls_scheduler, certificates, capsys, ca, client, said
):
    options = ["--scheduler", tls_scheduler, "--connect-timeout", "2", *_tls_options(certificates, ca, client)]
    assert main(_sweep(tmp_path / "out", *options)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and said in err and "--tls-ca-file" in err, err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_a_tls_scheduler_without_a_client_certificate_is_one_line(tmp_path, tls_scheduler, capsys):
    assert main(_sweep(tmp_path, "--scheduler", tls_scheduler)) == 2
    err = capsys.readouterr().err
    assert err == (
        f"pendulum-fmu sweep: error: {tls_scheduler} is TLS, and no client certificate is given: "
        "give --tls-ca-file, --tls-cert and --tls-key (security=tls_files(...) in Python), or set "
        "them in dask's configuration (distributed.comm.tls.ca-file, .client.cert, .client.key)\n"
    )


# --- a plain scheduler off the loopback ---------------------------------------------------


def test_a_plain_tcp_scheduler_off_the_loopback_draws_one_warning_naming_tls(tmp_path, capsys):
    # An address of TEST-NET-1 (RFC 5737): nothing answers there.
    assert main(_sweep(tmp_path, "--scheduler", "tcp://192.0.2.1:8786", "--connect-timeout", "0.5")) == 2
    warning, error = capsys.readouterr().err.splitlines()
    assert (
        warning.startswith("pendulum-fmu sweep: the scheduler at tcp://192.0.2.1:8786 is plain TCP")
        and "TLS" in warning
    )
    assert error.startswith("pendulum-fmu sweep: error: no dask scheduler answered at tcp://192.0.2.1:8786")
    # On the loopback: the error alone.
    assert main(_sweep(tmp_path, "--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "0.5")) == 2
    assert capsys.readouterr().err.count("\n") == 1


@pytest.mark.parametrize(
    "location, loopback",
    [
        ("127.0.0.1:8786", True),
        ("127.1.2.3:8786", True),
        ("localhost:8786", True),
        ("[::1]:8786", True),
        ("head:8786", False),
        ("10.0.0.5:8786", False),
        ("[2001:db8::1]:8786", False),
        ("localhost.example.org:8786", False),
    ],
)
def test_which_addresses_are_on_the_loopback(location, loopback):
    assert _on_loopback(location) is loopback


# --- what no run owns --------------------------------------------------------------------

# What a worker of an earlier run, woken after its run ended, leaves in a study's folder (issue
# 38): its chunk's two staged parts, and those it staged inside the hidden folder of a study that
# has since replaced the old one. Not parts of any table: bytes no reader could take.
LITTER = (
    "cases/_part-000009.0123456789abcdef0123456789abcdef.staged",
    "trajectories/_part-000009.0123456789abcdef0123456789abcdef.staged",
    ".overwrite.fedcba9876543210fedcba9876543210.partial/cases/_part-000003.0123456789abcdef0123456789abcdef.staged",
)


def _finished_study_with_litter(folder, tls_scheduler, certificates) -> tuple[Study, dict, dict]:
    """A finished study in folder, the litter added: (the study, the security, its parts' bytes)."""
    study = Study(sweep_grid([2.0, 4.0], [0.0]), stop_time=STOP_TIME)
    security = tls_files(certificates["ca"][0], *certificates["client"])
    run_sweep(study, output_dir=folder, scheduler=tls_scheduler, security=security, progress=False)
    parts = {path: path.read_bytes() for path in folder.glob("*/part-*")}
    for name in LITTER:
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(b"not a part of any table\n")
    return study, {"scheduler": tls_scheduler, "security": security}, parts


def test_what_no_run_owns_is_never_read_and_a_resume_clears_it(tmp_path, tls_scheduler, certificates):
    study, cluster, parts = _finished_study_with_litter(tmp_path, tls_scheduler, certificates)
    store = Store(*_local(tmp_path), format="parquet")
    assert 9 not in store.done_chunks() and sorted(store.read_cases(study.names)["case"].to_pylist()) == [0, 1]
    again = run_sweep(study, output_dir=tmp_path, resume=True, progress=False, **cluster)
    assert again.chunks_run == 0 and {path: path.read_bytes() for path in tmp_path.glob("*/part-*")} == parts
    assert not [name for name in LITTER if (tmp_path / name).exists()]
    assert not list(tmp_path.glob(".overwrite.*"))


def test_what_no_run_owns_is_cleared_before_a_run_connects(tmp_path, tls_scheduler, certificates):
    # A run that replaces the study and never gets a cluster: the folder keeps its study, and
    # loses the litter all the same, as the run cleared it before it connected.
    study, _, parts = _finished_study_with_litter(tmp_path, tls_scheduler, certificates)
    with pytest.raises(SchedulerUnreachable):
        run_sweep(study, output_dir=tmp_path, overwrite=True, scheduler="tcp://127.0.0.1:9", connect_timeout=0.5)
    assert {path: path.read_bytes() for path in tmp_path.glob("*/part-*")} == parts
    assert not list(tmp_path.glob("*/_part-*")) and not list(tmp_path.glob(".overwrite.*"))


def _local(folder) -> tuple:
    from fsspec.implementations.local import LocalFileSystem

    return LocalFileSystem(), str(folder)
