"""Who can drive a study's workers: the local cluster's certificates, made for its run, and the
client's TLS settings for a scheduler given by address.

A dask scheduler runs what any connected client sends (a task, client.run) on every worker, as
the user who started the workers; over plain TCP anyone who reaches its port connects. So the
local cluster speaks TLS, with a key and a self-signed certificate made for the run and held in
memory (the nannies hand them to their worker processes through a pipe): a process without
them fails the handshake, whoever it runs as. A scheduler given by address is its starter's: the
client connects with dask's security settings, from dask's configuration
(distributed.comm.tls.*) or given here, and a plain tcp:// one off the loopback draws a warning.
"""

from __future__ import annotations

import ipaddress
import os
import ssl
import warnings

from .._errors import InvalidInput, MissingDependency, MissingFile, UnencryptedScheduler, WrongType

# The client's settings, as dask's command line and its configuration name them.
TLS_FILES = {
    "tls_ca_file": ("--tls-ca-file", "distributed.comm.tls.ca-file"),
    "tls_client_cert": ("--tls-cert", "distributed.comm.tls.client.cert"),
    "tls_client_key": ("--tls-key", "distributed.comm.tls.client.key"),
}


def run_certificates():
    """A distributed.security.Security for a local cluster: a new key and self-signed
    certificate, in memory, for the scheduler, its workers and the client alike.
    """
    from distributed.security import Security

    try:
        return Security.temporary()
    except ImportError:
        raise MissingDependency(
            "the local dask cluster's TLS certificates need the cryptography package: pip install cryptography"
        ) from None


def tls_files(ca_file: str | os.PathLike, cert: str | os.PathLike, key: str | os.PathLike | None = None):
    """The security of a client of a TLS scheduler, from PEM files as dask names them.

    Parameters
    ----------
    ca_file : str or os.PathLike
        The certificate of the authority that signed the scheduler's and the workers'
        certificates (dask's --tls-ca-file).
    cert : str or os.PathLike
        The client's certificate, signed by an authority the scheduler trusts (--tls-cert); it
        may hold the key too.
    key : str or os.PathLike, optional
        The client's private key (--tls-key), where cert does not hold it.

    Returns
    -------
    distributed.security.Security
        Encryption required; run_sweep's security. The files are read when run_sweep connects.

    Raises
    ------
    TypeError
        A path that is neither a str nor an os.PathLike (run_sweep raises MissingFile for a path
        with no file, InvalidInput for a file that is no PEM certificate or key).

    Examples
    --------
    >>> from pendulum_fmu import tls_files
    >>> tls_files("ca.pem", "client.pem", "client.key").tls_client_cert
    'client.pem'
    """
    from distributed.security import Security

    return Security(
        require_encryption=True,
        tls_ca_file=os.fspath(ca_file),
        tls_client_cert=os.fspath(cert),
        tls_client_key=None if key is None else os.fspath(key),
    )


def client_security(scheduler: str, security):
    """The security a client of the scheduler connects with: the one given, else dask's
    configuration's; for a tls:// address checked here, so that a missing file or one that is no
    certificate is one line (MissingFile, InvalidInput) before anything connects. A tcp://
    address off the loopback warns (UnencryptedScheduler).
    """
    import dask
    from distributed.security import Security

    if security is None:
        security = Security()  # dask's configuration: distributed.comm.tls.*
    elif not isinstance(security, Security):
        raise WrongType(f"security is a distributed.security.Security, e.g. tls_files(...), not {security!r}")
    scheme, _, location = scheduler.rpartition("://")
    scheme = scheme or dask.config.get("distributed.comm.default-scheme")  # as dask reads "host:port"
    if scheme == "tls":
        _check_tls(scheduler, security)
    elif scheme == "tcp" and not _on_loopback(location):
        warnings.warn(
            f"the scheduler at {scheduler} is plain TCP: whoever reaches its port runs code on its "
            "workers; start it with TLS and connect with --scheduler tls://... --tls-ca-file, "
            "--tls-cert and --tls-key (the docs' Sweeps at scale)",
            UnencryptedScheduler,
            stacklevel=5,  # the caller of run_sweep (through dask_client and contextlib's __enter__)
        )
    return security


def _check_tls(scheduler: str, security) -> None:
    """The client's files for a tls:// scheduler there and readable as PEM, else one line."""
    for field, (option, setting) in TLS_FILES.items():
        value = getattr(security, field)
        if value and "\n" not in value and not os.path.isfile(value):  # a path, not PEM text
            raise MissingFile(f"TLS file {value} ({option}, or dask's {setting}): no such file; give the PEM file")
    try:
        context = security.get_connection_args("client")["ssl_context"]
    except (ssl.SSLError, OSError) as error:
        raise InvalidInput(
            f"the TLS files for {scheduler} cannot be read as a CA certificate, certificate and key "
            f"({getattr(error, 'reason', None) or error.strerror or error}): give the PEM files the cluster's CA signed"
        ) from None
    if context is None:
        raise InvalidInput(
            f"{scheduler} is TLS, and no client certificate is given: give --tls-ca-file, --tls-cert and "
            "--tls-key (security=tls_files(...) in Python), or set them in dask's configuration "
            "(distributed.comm.tls.ca-file, .client.cert, .client.key)"
        )


def _on_loopback(location: str) -> bool:
    """Whether a scheduler's host:port is on this machine's loopback (a name other than
    localhost is not looked up: that would be a network call, and its answer may change).
    """
    from distributed.comm.addressing import parse_host_port

    try:
        host, _ = parse_host_port(location)
    except ValueError:  # no port: dask's client refuses it, and says so
        return False
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
