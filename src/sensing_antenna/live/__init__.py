"""A real antenna in the loop: samples as they arrive, events as they happen (docs/live.md).

- :mod:`.wire`: the two wire formats, CSV lines (the recording format, line by line) and UDP
  datagrams; :class:`~.wire.StreamHeader`, what a stream says before its samples;
- :mod:`.events`: the events a listener gives, as typed records;
- :mod:`.listener`: :class:`~.listener.Listener`, one recording received live: the reader
  queues samples, a worker thread feeds them to the online estimator;
- :mod:`.inputs`: the readers of standard input and of a UDP socket;
- :mod:`.record`: what was received, written as a recording while it arrives;
- :mod:`.replay`: a recording sent at its own pace, to a text stream or over UDP;
- :mod:`.warm_up`: a listener's process made ready before the first sample arrives.
"""
