"""errors.py — the one exception of the package: a refusal of the server
(code -1 to -99, the protocol's error list) or a failure of libmeshcorr
(-100 and below), with its code, the code's name and the detail."""


class MeshcorrError(Exception):
    """code: the negative error code (-15 ...); name: mc_err_name's
    ("NOT_FOUND", "BAD_PARAMS", "MC_EARG"); description: mc_strerror's
    ("no such job"); message: the server's message or the local detail."""

    def __init__(self, code, name, description, message):
        self.code = code
        self.name = name
        self.description = description
        self.message = message or description
        super().__init__("%s (%d): %s" % (name, code, self.message))
