"""Campaigns: configuration, dispersion sampling, the runner and the result store."""

from .errors import ConfigError as ConfigError
from .loader import campaign_from_dict as campaign_from_dict
from .loader import load_campaign as load_campaign
from .loader import parse_campaign as parse_campaign
from .loader import read_campaign_tables as read_campaign_tables
from .loader import with_overrides as with_overrides
from .model import flight_params as flight_params
from .model import nominal_params as nominal_params
from .record import Campaign as Campaign
from .runner import run_chunks as run_chunks
from .store import ResultWriter as ResultWriter
from .store import ResumeError as ResumeError
