"""Campaigns: configuration, dispersion sampling, the runner and the result store."""

from .config import Campaign as Campaign
from .config import ConfigError as ConfigError
from .config import campaign_from_dict as campaign_from_dict
from .config import load_campaign as load_campaign
from .config import parse_campaign as parse_campaign
from .model import flight_params as flight_params
from .model import nominal_params as nominal_params
from .runner import run_chunks as run_chunks
from .store import ResultWriter as ResultWriter
from .store import ResumeError as ResumeError
