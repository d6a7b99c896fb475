"""The reports: the comparison product (`compare`: missions, step tests, Markdown and
HTML), the analysis report (`analysis`, with `aero`, `envelope`, `hover`, `takeoff`
sections and `analysis_plots`), the avionics section (`avionics`) and the Markdown /
HTML helpers (`markdown`)."""
