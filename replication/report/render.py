"""Jinja2 rendering of the report pages (self-contained: no script, font or style from outside)."""

from jinja2 import Environment, PackageLoader, select_autoescape
from markupsafe import Markup
import pandas as pd

ENVIRONMENT = Environment(loader=PackageLoader("replication.report", "templates"), autoescape=select_autoescape())


def render(template: str, **context) -> str:
    return ENVIRONMENT.get_template(template).render(**context)


def html_table(table: pd.DataFrame) -> Markup:
    return Markup(table.to_html(index=False, escape=True, border=0, na_rep=""))
