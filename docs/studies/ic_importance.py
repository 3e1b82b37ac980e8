#!/usr/bin/env python3
"""Importance-sampled records against the defaults (issue 28, docs/irradiance-splatting.md,
"Importance-sampled records").

usage: ic_importance.py TAG SIZE SPP [scenes...] [-- ic_splatting options]
  docs/studies/ic_image_size.py's runs (records, rays per record, debiased rel_rms with its
  standard error, stage times and the run's CPU seconds with the load, Monte Carlo at equal
  error where --mc-compare was given, the options and the commit), appended to $RESULTS,
  by default docs/results/ic_importance_rays.jsonl.

  docs/studies/ic_importance.py defaults 256x256 1024
  docs/studies/ic_importance.py imp-256 256x256 1024 -- --importance-rays
"""
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
os.environ.setdefault('RESULTS', os.path.join(root, 'docs/results/ic_importance_rays.jsonl'))
os.execv(sys.executable, [sys.executable, os.path.join(here, 'ic_image_size.py')] + sys.argv[1:])
