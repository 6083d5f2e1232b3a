"""The catalog's one error class, and the context that turns a failed HDF5 write into it."""


class CatalogError(RuntimeError):
    """A catalog that cannot be created, written or read; the message names the file.

    broken: a write failed, and HDF5 may fail again (or crash) on anything else done with
    the open file, closing included: the caller should end the process without touching it.
    collective: raised on every rank alike (no abort of the others is needed).
    """

    def __init__(self, message, broken=False, collective=False):
        super().__init__(message)
        self.broken = broken
        self.collective = collective


def reason(err):
    """The useful part of an HDF5 error: its errno text where it names one, else the first line."""
    text = str(err)
    if "error message = '" in text:
        return text.split("error message = '", 1)[1].split("'", 1)[0]
    return text.splitlines()[0] if text else type(err).__name__


class writing:
    """Context of a write: any HDF5 failure becomes one CatalogError (broken) naming the file and what."""

    def __init__(self, path, what):
        self.path, self.what = path, what

    def __enter__(self):
        return self

    def __exit__(self, kind, err, tb):
        if err is None or isinstance(err, CatalogError) or not isinstance(err, Exception):
            return False
        raise CatalogError(f"{self.path}: writing {self.what} failed ({reason(err)}); what was committed "
                           f"before stays readable; continue with `python -m ensemble resume`",
                           broken=True) from None

