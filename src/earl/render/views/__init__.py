"""One module per diagram of the manual: system (Figure 8), agent (Figure 10), fsm (Figure 12),
activity (Figure 15) and types (Figures 9 and 11).  Each builds DOT text from the model only."""
