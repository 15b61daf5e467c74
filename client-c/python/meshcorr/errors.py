"""errors.py — the one exception of the package: a refusal of the server
(code -1 to -99, the protocol's error list) or a failure of libmeshcorr
(-100 and below), with its code, the code's name and the detail."""


class MeshcorrError(Exception):
    """code: the negative error code (MC_ENOT_FOUND = -15 ...); name: what
    mc_strerror calls it; message: the server's message or the local detail."""

    def __init__(self, code, name, message):
        self.code = code
        self.name = name
        self.message = message or name
        super().__init__("%s (%d): %s" % (name, code, self.message))
