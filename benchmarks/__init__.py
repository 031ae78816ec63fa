"""The speed-against-error benchmark of pam2exu (run ``python benchmarks/speed_vs_error.py``).

Measuring: ``cases``, ``plain_exudyn``, ``measure``, ``sections``, ``backends`` (the two
backends side by side), ``clearance``, ``dynamics``, ``studies`` (a study's variants per
second, also ``python benchmarks/studies.py`` alone), ``natural_speed`` (the natural
backend where users live, also ``python benchmarks/natural_speed.py`` alone); reporting:
``report``, ``report_backends``, ``plot``; ``speed_vs_error`` is the command line. Not
installed with pam2exu; the references it checks against are the top-level ``references``
package.
"""
