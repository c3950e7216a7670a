"""Ed25519 keys for signing an FMU's build record (`export --sign KEY`, `verify --public-key KEY`),
through the cryptography package: a key is a PEM file, as `openssl genpkey -algorithm ed25519`
writes it (and `openssl pkey -in KEY -pubout` its public key).
"""

from __future__ import annotations

import os

from .._errors import InvalidInput, MissingFile


def _pem(path: str | os.PathLike, what: str) -> bytes:
    try:
        with open(path, "rb") as file:
            return file.read(64 * 1024)
    except FileNotFoundError:
        raise MissingFile(f"{os.fspath(path)}: no such {what} (a PEM file)") from None
    except OSError as error:
        raise InvalidInput(f"{os.fspath(path)}: cannot read the {what} ({error.strerror})") from None


def load_private_key(path: str | os.PathLike):
    """The Ed25519 private key in a PEM file (unencrypted)."""
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
    from cryptography.hazmat.primitives.serialization import load_pem_private_key

    try:
        key = load_pem_private_key(_pem(path, "private key"), password=None)
    except (ValueError, TypeError) as error:
        raise InvalidInput(f"{os.fspath(path)}: not an unencrypted PEM private key ({error})") from None
    if not isinstance(key, Ed25519PrivateKey):
        raise InvalidInput(f"{os.fspath(path)}: not an Ed25519 key (openssl genpkey -algorithm ed25519 makes one)")
    return key


def load_public_key(path: str | os.PathLike):
    """The Ed25519 public key in a PEM file."""
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey
    from cryptography.hazmat.primitives.serialization import load_pem_public_key

    try:
        key = load_pem_public_key(_pem(path, "public key"))
    except (ValueError, TypeError) as error:
        raise InvalidInput(f"{os.fspath(path)}: not a PEM public key ({error})") from None
    if not isinstance(key, Ed25519PublicKey):
        raise InvalidInput(f"{os.fspath(path)}: not an Ed25519 public key")
    return key
