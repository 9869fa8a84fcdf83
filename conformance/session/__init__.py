"""One pytest run beyond the checks themselves: which checks run (``selection``: --shard, -k words
that match nothing, runs that checked nothing of the sync), in which order (``ordering``), and in which
process (``isolation``: a serial run in a worker, a crashed worker's check made a failure). Imports
``checks`` and below; the plugin (:mod:`conformance.plugin`) is their only user (internal)."""
