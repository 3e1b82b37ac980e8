# embedding: the renderer-like example checks its --out before it renders.
bounce_cli_refusal("an --out of an unknown image format" PROGRAM embedding MATCH "--out.*not a writable image file"
                   ARGS --out embedding_x.unknownformat)
bounce_cli_refusal("an --out in /proc" PROGRAM embedding MATCH "--out.*not a writable image file" ARGS --out /proc/e.png)
