"""Identification of model parameters from measurements."""

from gripsense.identify.contact_fit import fit_contact_length

__all__ = ["fit_contact_length"]
