"""bulkflow: the Python side of the bulkflow solver (post-processing, theory, studies).

Subpackages are imported on demand so that ``import bulkflow`` stays cheap and needs no
plotting library.
"""

__version__ = "0.1.0"
